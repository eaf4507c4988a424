"""`Log.frames()`: the rows of `wobblog decode`, value for value, handed to
pyarrow, Polars, pandas and DuckDB through `__arrow_c_stream__`."""

import warnings
from datetime import datetime, timezone

import duckdb
import polars as pl
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import wobblog
from conftest import cli, encode


def decoded_parquet(log, tmp_path, *args):
    out = tmp_path / "frames.parquet"
    cli("decode", log, "-o", out, *args)
    return pq.read_table(out)


def open_quietly(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", wobblog.DamageWarning)
        return wobblog.open(path)


def assert_same_table(ours: pa.Table, theirs: pa.Table):
    assert ours.column_names == theirs.column_names
    assert ours.num_rows == theirs.num_rows
    for name in ours.column_names:
        a, b = ours.column(name), theirs.column(name)
        # Text is held as Polars holds it; Parquet has no such type.
        expected = pa.string_view() if b.type == pa.string() else b.type
        assert a.type == expected, name
        assert a.to_pylist() == b.to_pylist(), name


def test_frames_equal_the_cli_parquet(golden, wobble_log, campaign, tmp_path):
    logs = [*golden.values(), wobble_log, campaign / "RUN00002.WBL"]
    for log in logs:
        ours = pa.table(open_quietly(log).frames())
        assert_same_table(ours, decoded_parquet(log, tmp_path))


def test_columns_and_a_boot_time_window_equal_the_cli(wobble_log, tmp_path):
    frames = wobblog.open(wobble_log).frames(
        columns=["steer_deg", "t_s", "speed_mps"], start=10.0, end=12.5)
    theirs = decoded_parquet(wobble_log, tmp_path, "--columns",
                             "steer_deg,t_s,speed_mps", "--from", "10", "--to", "12.5")
    assert frames.column_names == ["steer_deg", "t_s", "speed_mps"]
    assert frames.num_rows == 251
    assert_same_table(pa.table(frames), theirs)


def test_a_utc_window_equals_the_cli(campaign, tmp_path):
    log = campaign / "RUN00001.WBL"
    start = datetime(2020, 3, 18, 13, 28, 22, 500000, tzinfo=timezone.utc)
    end = datetime(2020, 3, 18, 13, 28, 24, tzinfo=timezone.utc)
    frames = pa.table(wobblog.open(log).frames(start=start, end=end))
    theirs = decoded_parquet(log, tmp_path, "--from", "2020-03-18T13:28:22.5Z",
                             "--to", "2020-03-18T13:28:24Z")
    assert frames.num_rows == 151
    assert_same_table(frames, theirs)
    assert frames.column("utc").to_pylist()[0] == start


def test_utc_is_a_utc_timestamp(campaign):
    df = wobblog.open(campaign / "RUN00001.WBL").frames(columns=["t_s", "utc"]).to_polars()
    assert df.schema["utc"] == pl.Datetime("us", "UTC")
    first = df.row(0, named=True)
    assert first["utc"] == datetime(2020, 3, 18, 13, 28, 20, tzinfo=timezone.utc)


def test_every_consumer_reads_the_stream(wobble_log):
    frames = wobblog.open(wobble_log).frames()
    n = frames.num_rows
    assert n == len(frames) == 3000
    assert pl.DataFrame(frames).height == n
    assert frames.to_polars().equals(pl.DataFrame(frames))
    assert frames.to_arrow().num_rows == n
    pandas_df = frames.to_pandas()
    assert pandas_df.shape == (n, 14)
    # DuckDB finds the table by its Python name and reads the stream.
    [(count, top)] = duckdb.sql("select count(*), max(steer_deg) from frames").fetchall()
    assert count == n
    assert top == pl.DataFrame(frames)["steer_deg"].max()
    # The table can be read again: each read gets a fresh stream.
    assert pa.table(frames).num_rows == n


def test_polars_reads_what_read_parquet_reads(golden, tmp_path):
    out = tmp_path / "gps.parquet"
    cli("decode", golden["gps"], "-o", out)
    assert wobblog.open(golden["gps"]).frames().to_polars().equals(pl.read_parquet(out))


def test_a_stream_capsule_is_what_the_interface_names(golden):
    frames = wobblog.open(golden["clean"]).frames()
    capsule = frames.__arrow_c_stream__()
    assert type(capsule).__name__ == "PyCapsule"
    assert "arrow_array_stream" in repr(capsule)
    assert "arrow_schema" in repr(frames.__arrow_c_schema__())
    # An unread capsule is released without a leak or a crash.
    del capsule


def test_an_unknown_column_names_the_log_and_the_columns(golden):
    log = wobblog.open(golden["clean"])
    with pytest.raises(wobblog.WobblogError, match=r'clean\.WBL: no column "roll_deg"; the columns are t_s,'):
        log.frames(columns=["t_s", "roll_deg"])


def test_a_window_without_frames_is_an_error(golden):
    log = wobblog.open(golden["clean"])
    with pytest.raises(wobblog.WobblogError, match=r"clean\.WBL"):
        log.frames(start=100.0, end=200.0)
    with pytest.raises(wobblog.WobblogError, match=r"clean\.WBL"):
        log.frames(start=0.4, end=0.2)


def test_a_utc_window_on_a_log_without_utc_is_an_error(golden):
    with pytest.raises(wobblog.WobblogError, match=r"clean\.WBL"):
        wobblog.open(golden["clean"]).frames(
            start=datetime(2020, 1, 1, tzinfo=timezone.utc))


def test_a_naive_datetime_is_refused():
    with pytest.raises(TypeError, match="timezone"):
        wobblog.open(
            __import__("conftest").GOLDEN / "clean.WBL").frames(start=datetime(2020, 1, 1))


def test_frames_of_a_damaged_log_warn_and_keep_the_rest(damaged_copy, wobble_log, tmp_path):
    with pytest.warns(wobblog.DamageWarning, match=r"RUN00009\.WBL"):
        log = wobblog.open(damaged_copy)
    frames = pa.table(log.frames())
    whole = wobblog.open(wobble_log).frames().num_rows
    assert 0 < frames.num_rows < whole
    assert_same_table(frames, decoded_parquet(damaged_copy, tmp_path))


def test_a_window_across_time_jumps_equals_the_cli(golden, tmp_path):
    # Boot time jumps forward to 5.2 s and back to 1.0 s: the window keeps
    # rows of the first and the last segment, not of the middle one.
    log = open_quietly(golden["timejump"])
    ours = pa.table(log.frames(start=0.1, end=1.02))
    theirs = decoded_parquet(golden["timejump"], tmp_path, "--from", "0.1", "--to", "1.02")
    assert_same_table(ours, theirs)
    times = ours.column("t_s").to_pylist()
    assert min(times) < 0.5 and max(times) >= 1.0 and not any(t > 5 for t in times)


def test_a_window_across_batches_equals_the_cli(tmp_path):
    # 70 000 frames: more than one record batch (65 536 rows each).
    lines = ["t_s,steer_deg,speed_mps"]
    lines.extend(f"{i / 100:.2f},{(i % 300) / 100:.2f},4.5" for i in range(70_000))
    log = encode("\n".join(lines) + "\n", tmp_path, "RUN00001")
    frames = wobblog.open(log).frames(columns=["t_s", "steer_deg"], start=600.0, end=700.0)
    theirs = decoded_parquet(log, tmp_path, "--columns", "t_s,steer_deg",
                             "--from", "600", "--to", "700")
    assert_same_table(pa.table(frames), theirs)
    assert pl.DataFrame(frames).equals(pl.from_arrow(theirs))
