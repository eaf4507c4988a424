"""The type stubs describe what the package exports, so editors complete
every name and no stale one."""

import ast
from pathlib import Path

import wobblog
import wobblog.model

PACKAGE = Path(wobblog.__file__).parent


def stub_names(name, module_level_only=True):
    tree = ast.parse((PACKAGE / name).read_text())
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.ImportFrom):
            names.update(alias.asname or alias.name for alias in node.names)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
    return {n for n in names if not n.startswith("_") or n == "__version__"}


def test_the_package_stub_names_every_export():
    names = stub_names("__init__.pyi") - {"Any", "Optional", "Sequence", "Union"}
    assert names == set(wobblog.__all__)


def test_the_model_stub_names_every_export():
    names = stub_names("model.pyi") - {"Any", "Optional", "Sequence", "Union", "Table", "Path"}
    assert names == set(wobblog.model.__all__)


def test_every_native_function_has_a_docstring():
    for name in wobblog.__all__:
        obj = getattr(wobblog, name)
        if callable(obj):
            assert obj.__doc__ and len(obj.__doc__) > 20, name
