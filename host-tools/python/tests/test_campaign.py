"""`wobblog.scan` and `wobblog.summary`: every log of a card or a folder of
cards, equal to `wobblog export`'s frames dataset and `wobblog summary --json`."""

import shutil
import warnings

import polars as pl
import pyarrow as pa
import pytest

import wobblog
from conftest import cli, cli_json_lines


def exported_frames(directory, tmp_path):
    out = tmp_path / "dataset"
    cli("export", directory, "-o", out)
    return pl.read_parquet(out / "frames", hive_partitioning=True)


def scanned(directory, **kwargs):
    return pl.DataFrame(wobblog.scan(directory, **kwargs))


def test_scan_of_a_card_equals_the_exported_dataset(campaign, tmp_path):
    ours = scanned(campaign)
    theirs = exported_frames(campaign, tmp_path)
    assert ours.columns[-1] == "run" and "card" not in ours.columns
    assert ours.height == 8 * 1000
    assert ours["run"].unique().sort().to_list() == list(range(8))
    # Hive readers type the partition column themselves: compare the values.
    theirs = theirs.select(ours.columns).with_columns(pl.col("run").cast(pl.Int64))
    assert ours.equals(theirs)


def test_scan_of_a_folder_of_cards_has_a_card_column(campaign, tmp_path):
    cards = tmp_path / "cards"
    for card, runs in (("anna", [0, 1]), ("ben", [2])):
        (cards / card).mkdir(parents=True)
        for run in runs:
            name = f"RUN{run:05d}.WBL"
            shutil.copyfile(campaign / name, cards / card / name)
    ours = scanned(cards)
    assert ours.columns[-2:] == ["run", "card"]
    theirs = exported_frames(cards, tmp_path)
    theirs = theirs.select(ours.columns).with_columns(pl.col("run").cast(pl.Int64))
    assert ours.sort(["card", "run", "t_s"]).equals(theirs.sort(["card", "run", "t_s"]))
    assert ours.group_by("card").len().sort("card")["len"].to_list() == [2000, 1000]


def test_scan_columns_and_window(campaign):
    scan = wobblog.scan(campaign, columns=["t_s", "steer_deg"], start=2.0, end=2.99)
    assert scan.column_names == ["t_s", "steer_deg", "run"]
    df = pl.DataFrame(scan)
    assert df.height == 8 * 100
    per_run = pl.DataFrame(wobblog.open(campaign / "RUN00005.WBL").frames(
        columns=["t_s", "steer_deg"], start=2.0, end=2.99))
    assert df.filter(pl.col("run") == 5).drop("run").equals(per_run)


def test_scan_is_read_lazily_log_by_log(campaign):
    scan = wobblog.scan(campaign)
    assert len(scan.logs) == 8
    reader = pa.RecordBatchReader.from_stream(scan)
    first = reader.read_next_batch()
    # One log per batch here (1000 frames each): the first holds run 0 only.
    assert set(first.column("run").to_pylist()) == {0}
    assert sum(b.num_rows for b in reader) == 7000


def test_scan_warns_of_an_unreadable_log_and_keeps_the_others(campaign, tmp_path):
    card = tmp_path / "card"
    shutil.copytree(campaign, card)
    (card / "RUN00099.WBL").write_bytes(b"\x55" * 4096)
    with pytest.warns(wobblog.DamageWarning, match=r"RUN00099\.WBL: no valid log block"):
        df = scanned(card)
    assert df["run"].unique().sort().to_list() == list(range(8))


def test_scan_of_a_folder_without_logs_is_an_error(tmp_path):
    with pytest.raises(wobblog.WobblogError, match=tmp_path.name):
        wobblog.scan(tmp_path)


def test_summary_equals_the_cli(campaign, wobble_log):
    ours = wobblog.summary(campaign)
    assert ours == cli_json_lines("summary", campaign, "--json")
    assert len(ours) == 8
    wobble_card = wobble_log.parent
    assert wobblog.summary(wobble_card) == cli_json_lines("summary", wobble_card, "--json")
    assert wobblog.summary(wobble_card)[0]["wobble_speed_mps"] is not None


def test_summary_warns_of_an_unreadable_log(campaign, tmp_path):
    card = tmp_path / "card"
    shutil.copytree(campaign, card)
    (card / "RUN00099.WBL").write_bytes(b"\x55" * 4096)
    with pytest.warns(wobblog.DamageWarning, match=r"RUN00099\.WBL"):
        rows = wobblog.summary(card)
    assert [r["log"] for r in rows] == [f"RUN{i:05d}.WBL" for i in range(8)]


def test_scan_as_a_lazy_frame_reads_only_what_the_query_needs(campaign, tmp_path):
    scan = wobblog.scan(campaign)
    whole = scan.to_polars()
    lazy = scan.lazy()
    assert isinstance(lazy, pl.LazyFrame)
    assert lazy.collect_schema() == whole.schema
    assert lazy.collect().equals(whole)
    columns = ["run", "t_s", "steer_deg"]
    query = lazy.filter(pl.col("run") == 5).select(columns)
    assert query.collect().equals(whole.filter(pl.col("run") == 5).select(columns))
    assert lazy.head(1500).collect().equals(whole.head(1500))
    # A log past the rows asked for is never read: its damage is not met.
    card = tmp_path / "card"
    shutil.copytree(campaign, card)
    (card / "RUN00099.WBL").write_bytes(b"\x55" * 4096)
    with warnings.catch_warnings():
        warnings.simplefilter("error", wobblog.DamageWarning)
        assert wobblog.scan(card).lazy().head(10).collect().height == 10
    with pytest.warns(wobblog.DamageWarning, match=r"RUN00099\.WBL"):
        assert wobblog.scan(card).lazy().collect().height == 8 * 1000
