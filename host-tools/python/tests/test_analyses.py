"""Events, episodes, kicks, roll and the margin from Python equal the CLI's
JSON on the same logs."""

import warnings

import pyarrow as pa
import pytest

import wobblog
from conftest import cli_json, cli_json_lines


def test_events_equal_the_cli(golden):
    found = 0
    for path in golden.values():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", wobblog.DamageWarning)
            events = wobblog.open(path).events()
        assert events == cli_json_lines("events", path, "--json"), path.name
        found += len(events)
    assert found > 0


def test_episodes_equal_the_cli(wobble_log):
    ours = wobblog.open(wobble_log).episodes()
    assert ours == cli_json("wobble", wobble_log, "--json")
    assert len(ours["episodes"]) >= 1
    assert ours["wobble_speed_mps"] is not None


def test_episodes_in_a_window_equal_the_cli(wobble_log):
    ours = wobblog.open(wobble_log).episodes(start=0.0, end=5.0)
    assert ours == cli_json("wobble", wobble_log, "--json", "--from", "0", "--to", "5")
    assert ours["episodes"] == []


def test_episodes_of_a_damaged_log_warn_and_equal_the_cli(damaged_copy):
    with pytest.warns(wobblog.DamageWarning):
        log = wobblog.open(damaged_copy)
    ours = log.episodes()
    assert ours == cli_json("wobble", damaged_copy, "--json")
    assert ours["episodes"]


def test_kicks_are_the_margin_report_rows(campaign):
    report = cli_json("margin", campaign, "--json")
    rows = []
    for path in sorted(campaign.glob("*.WBL")):
        rows.extend(wobblog.open(path).kicks())
    expected = [{k: v for k, v in row.items() if k != "used"} for row in report["kicks"]]
    assert len(rows) == 8
    assert rows == expected


def test_kicks_from_the_card_only(campaign):
    log = campaign / "RUN00004.WBL"
    card = cli_json("margin", log, "--json", "--kicks", "card")["kicks"]
    ours = wobblog.open(log).kicks(kicks="card")
    assert ours == [{k: v for k, v in row.items() if k != "used"} for row in card]
    assert all(row["source"] == "card" for row in ours)


def test_an_unknown_kick_choice_is_named(campaign):
    with pytest.raises(wobblog.WobblogError, match=r'kicks="both": one of best, card, host'):
        wobblog.open(campaign / "RUN00000.WBL").kicks(kicks="both")


def test_margin_equals_the_cli(campaign):
    ours = wobblog.margin(campaign)
    assert ours == cli_json("margin", campaign, "--json")
    assert ours.wobble_speed_mps == pytest.approx(4.0, abs=0.5)
    lo, hi = ours.ci95_mps
    assert lo < ours.wobble_speed_mps
    assert ours.method.startswith("damping extrapolation")
    assert len(ours.kicks) == 8


def test_margin_of_a_list_of_logs_and_options_equals_the_cli(campaign):
    logs = sorted(campaign.glob("*.WBL"))[:7]
    ours = wobblog.margin(logs, kicks="host", trend="quadratic", ride_margin_pct=20)
    theirs = cli_json("margin", *logs, "--json", "--kicks", "host",
                      "--trend", "quadratic", "--ride-margin", "20")
    assert ours == theirs
    assert ours.trend == "quadratic" and ours.ride_margin == 0.2


def test_margin_with_a_model_equals_the_cli(campaign):
    from conftest import ROOT
    params = ROOT / "host-tools" / "bicycle-model" / "params" / "test-bicycle.toml"
    ours = wobblog.margin(campaign, model=params)
    assert ours == cli_json("margin", campaign, "--json", "--model", params)
    assert "model" in ours


def test_margin_goes_on_past_a_log_that_cannot_be_read(campaign, tmp_path):
    junk = tmp_path / "JUNK.WBL"
    junk.write_bytes(b"\x55" * 4096)
    logs = [*sorted(campaign.glob("*.WBL")), junk]
    with pytest.warns(wobblog.DamageWarning, match=r"JUNK\.WBL"):
        ours = wobblog.margin(logs)
    assert ours == cli_json("margin", campaign, "--json")


def test_margin_of_nothing_readable_is_an_error(tmp_path):
    junk = tmp_path / "JUNK.WBL"
    junk.write_bytes(b"\x55" * 4096)
    with pytest.raises(wobblog.WobblogError, match=r"JUNK\.WBL"):
        wobblog.margin(junk)
    with pytest.raises(wobblog.WobblogError, match="no \\*.WBL logs"):
        wobblog.margin(tmp_path / "..")  if False else wobblog.margin(_empty_dir(tmp_path))


def _empty_dir(tmp_path):
    d = tmp_path / "empty"
    d.mkdir()
    return d


def test_roll_has_one_angle_per_frame(wobble_log):
    log = wobblog.open(wobble_log)
    roll = pa.table(log.roll())
    frames = pa.table(log.frames(columns=["t_s"]))
    assert roll.column_names == ["t_s", "roll_deg"]
    assert roll.column("t_s").to_pylist() == frames.column("t_s").to_pylist()
    # The corpus ride has no IMU data: level, so every angle is zero.
    assert all(abs(v) < 1e-9 for v in roll.column("roll_deg").to_pylist())
