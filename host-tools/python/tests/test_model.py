"""`wobblog.model`: eigenvalues, critical speeds and parameters equal
`wobblog model eig --format jsonl` on the same parameter files."""

import numpy as np
import pyarrow as pa
import pytest

import wobblog
import wobblog.model
from conftest import ROOT, cli_json_lines

PARAMS = ROOT / "host-tools" / "bicycle-model" / "params"
BENCHMARK_TXT = (ROOT / "host-tools" / "bicycle-model" / "tests" / "data"
                 / "bicycleparameters" / "PistaBenchmark.txt")


def cli_eig(params, speeds, *args):
    lines = cli_json_lines("model", "eig", params, "--speeds", speeds, "--format", "jsonl", *args)
    rows = [line for line in lines if "critical_speed_mps" not in line]
    critical = [line for line in lines if "critical_speed_mps" in line]
    return rows, critical


@pytest.mark.parametrize("params", [PARAMS / "benchmark.toml",
                                    PARAMS / "test-bicycle.toml", BENCHMARK_TXT])
def test_eig_and_critical_speeds_equal_the_cli(params):
    model = wobblog.model.load(params)
    rows, critical = cli_eig(params, "0:8:0.5")
    ours = pa.table(model.eig("0:8:0.5")).to_pylist()
    assert ours == rows
    assert len(ours) == 17 * len(model.state_names)
    assert model.critical_speeds("0:8:0.5") == critical


def test_the_whipple_limit_equals_the_cli():
    params = PARAMS / "test-bicycle.toml"
    model = wobblog.model.load(params, variant="whipple")
    rows, critical = cli_eig(params, "0:10:1", "--whipple")
    assert pa.table(model.eig("0:10:1")).to_pylist() == rows
    assert model.critical_speeds("0:10:1") == critical
    assert len(model.state_names) == 4


def test_the_benchmark_weave_speed():
    # Meijaard et al. (2007): the weave speed of the benchmark is 4.292 m/s.
    critical = wobblog.model.load(PARAMS / "benchmark.toml").critical_speeds()
    weave = [c for c in critical if c["mode"] == "weave"]
    assert weave[0]["critical_speed_mps"] == pytest.approx(4.2924, abs=1e-3)


def test_the_state_matrix_has_the_table_s_eigenvalues():
    model = wobblog.model.load(PARAMS / "test-bicycle.toml")
    a = model.state_matrix(5.0)
    n = len(model.state_names)
    assert a.shape == (n, n)
    ours = sorted(np.linalg.eigvals(a), key=lambda v: (round(v.imag, 6), round(v.real, 6)))
    table = [r for r in pa.table(model.eig([5.0])).to_pylist()]
    theirs = sorted((complex(r["re_per_s"], r["im_rad_per_s"]) for r in table),
                    key=lambda v: (round(v.imag, 6), round(v.real, 6)))
    assert np.allclose(ours, theirs, atol=1e-6)


def test_with_params_equals_a_file_with_the_changed_value(tmp_path):
    source = PARAMS / "benchmark.toml"
    model = wobblog.model.load(source)
    assert model.params["geometry.trail"] == 0.08
    assert model.units["geometry.trail"] == "m"
    changed = model.with_params({"geometry.trail": 0.06})
    assert changed.params["geometry.trail"] == 0.06
    assert model.params["geometry.trail"] == 0.08
    text = source.read_text().replace(
        'trail = { value = 0.08,', 'trail = { value = 0.06,')
    edited = tmp_path / "trail.toml"
    edited.write_text(text)
    rows, critical = cli_eig(edited, "0:10:0.5")
    assert pa.table(changed.eig("0:10:0.5")).to_pylist() == rows
    assert changed.critical_speeds("0:10:0.5") == critical
    assert critical != model.critical_speeds("0:10:0.5")


def test_model_errors_name_the_file_and_the_cause(tmp_path):
    model = wobblog.model.load(PARAMS / "benchmark.toml")
    with pytest.raises(wobblog.WobblogError, match=r"benchmark\.toml: geometry\.trial: no such parameter"):
        model.with_params({"geometry.trial": 0.06})
    with pytest.raises(wobblog.WobblogError, match=r"speeds: .*FROM:TO:STEP"):
        model.eig("0-10")
    with pytest.raises(wobblog.WobblogError, match="variant"):
        wobblog.model.load(PARAMS / "benchmark.toml", variant="rigid")
    bad = tmp_path / "bad.toml"
    bad.write_text("this is = = not toml")
    with pytest.raises(wobblog.WobblogError, match=r"bad\.toml"):
        wobblog.model.load(bad)
    with pytest.raises(wobblog.WobblogError, match=r"missing\.toml"):
        wobblog.model.load(tmp_path / "missing.toml")
