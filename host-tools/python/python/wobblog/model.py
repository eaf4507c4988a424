"""The linear bicycle models of a parameter file, as ``wobblog model eig``
evaluates them: eigenvalues by mode, critical speeds, the state matrix."""

from ._wobblog import Model
from ._wobblog import load_model as load

__all__ = ["Model", "load"]
