"""`wobblog.episodes` and `wobblog.kicks` on arrays from any source equal
the analyses of the log the arrays came from."""

import math

import numpy as np
import polars as pl
import pyarrow as pa
import pytest

import wobblog


def columns_of(log_path, *names):
    frames = wobblog.open(log_path).frames(columns=list(names))
    return pl.DataFrame(frames)


def without_log(report):
    return {k: v for k, v in report.items() if k != "log"}


def test_episodes_of_a_log_s_arrays_equal_the_log_s(wobble_log):
    df = columns_of(wobble_log, "t_s", "steer_deg", "speed_mps")
    ours = wobblog.episodes(df["steer_deg"], df["speed_mps"], t_s=df["t_s"])
    theirs = wobblog.open(wobble_log).episodes()
    assert ours["log"] == "<arrays>"
    assert ours["episodes"]
    assert without_log(ours) == without_log(theirs)


def test_every_kind_of_array_gives_the_same_episodes(wobble_log):
    df = columns_of(wobble_log, "steer_deg", "speed_mps")
    by_polars = wobblog.episodes(df["steer_deg"], df["speed_mps"])
    by_numpy = wobblog.episodes(df["steer_deg"].to_numpy(), np.asarray(df["speed_mps"]))
    table = df.to_arrow()
    by_arrow = wobblog.episodes(table.column("steer_deg"), pa.array(df["speed_mps"].to_list()))
    by_pandas = wobblog.episodes(df.to_pandas()["steer_deg"], df["speed_mps"].to_list())
    assert by_polars == by_numpy == by_arrow == by_pandas
    # Times from 0 s, where the log's start at 0.00 s too.
    assert by_polars["episodes"] == wobblog.open(wobble_log).episodes()["episodes"]


def test_kicks_of_a_log_s_arrays_equal_the_host_s_kicks(campaign):
    log = campaign / "RUN00004.WBL"
    # The logger's configuration holds the wheel as a 32-bit float.
    wheel = float(np.float32(wobblog.open(log).config["wheel.circumference_m"]))
    df = columns_of(log, "t_s", "steer_deg", "speed_mps")
    ours = wobblog.kicks(df["steer_deg"], df["speed_mps"], t_s=df["t_s"],
                         wheel_circumference_m=wheel)
    theirs = wobblog.open(log).kicks(kicks="host")
    assert len(ours) == 1
    assert [without_log(k) for k in ours] == [without_log(k) for k in theirs]
    # The logger's default wheel when none is given (this campaign's is it).
    assert wobblog.kicks(df["steer_deg"], df["speed_mps"], t_s=df["t_s"]) == ours


def test_other_rates_are_refused_clearly():
    with pytest.raises(wobblog.WobblogError, match=r"rate_hz=200.*100 Hz"):
        wobblog.episodes([0.0] * 10, [3.0] * 10, rate_hz=200)


def test_times_that_do_not_step_by_10_ms_are_refused():
    t = [0.0, 0.01, 0.015, 0.03]
    with pytest.raises(wobblog.WobblogError, match=r"t_s\[2\] - t_s\[1\]"):
        wobblog.episodes([0.0] * 4, [3.0] * 4, t_s=t)


def test_bad_samples_are_named():
    with pytest.raises(wobblog.WobblogError, match="steer_deg has 3 samples, speed_mps 2"):
        wobblog.episodes([0.0] * 3, [3.0] * 2)
    with pytest.raises(wobblog.WobblogError, match=r"speed_mps\[1\] is missing"):
        wobblog.episodes([0.0] * 3, pa.array([3.0, None, 3.0]))
    with pytest.raises(wobblog.WobblogError, match="sample 1 is not a finite number"):
        wobblog.episodes([0.0, math.nan, 0.0], [3.0] * 3)
    with pytest.raises(wobblog.WobblogError, match="wheel_circumference_m=-1"):
        wobblog.kicks([0.0] * 3, [3.0] * 3, wheel_circumference_m=-1)


def test_a_gap_in_the_times_is_allowed(wobble_log):
    df = columns_of(wobble_log, "t_s", "steer_deg", "speed_mps")
    cut = df.filter((pl.col("t_s") < 5.0) | (pl.col("t_s") > 6.0))
    ours = wobblog.episodes(cut["steer_deg"], cut["speed_mps"], t_s=cut["t_s"])
    assert ours["episodes"]
