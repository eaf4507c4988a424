"""`wobblog.open`: a log's info, config and damage, as `wobblog info --json`
and `wobblog config` give them; errors and warnings."""

import io
import os
import subprocess
import sys
import threading
import warnings

import pyarrow as pa
import pytest

import wobblog
from conftest import cli, cli_json, frozen


def test_info_is_the_cli_json_for_every_golden_log(golden):
    assert len(golden) >= 6
    for name, path in golden.items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", wobblog.DamageWarning)
            log = wobblog.open(path)
        assert log.info == cli_json("info", path, "--json"), name


def test_config_is_the_cli_config_file(golden, campaign):
    # A golden log's header and a log the encoder ran the detector over.
    for path in (golden["clean"], campaign / "RUN00000.WBL"):
        log = wobblog.open(path)
        lines = [line for line in cli("config", path).splitlines()
                 if line and not line.startswith("#")]
        assert len(log.config) == len(lines) > 0
        assert [f"{k}={v}" for k, v in log.config.items()] == lines


def test_a_clean_log_gives_no_warning(golden):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        log = wobblog.open(golden["clean"])
    assert log.damage["damaged_blocks"] == 0 and log.damage["lost_blocks"] == 0


def test_damage_warns_and_the_rest_is_kept(golden):
    with pytest.warns(wobblog.DamageWarning, match=r"powercut\.WBL: 512 bytes skipped"):
        log = wobblog.open(golden["powercut"])
    info = cli_json("info", golden["powercut"], "--json")
    assert log.damage["damaged_blocks"] == info["damaged_blocks"] == 1
    assert log.damage["losses"] == info["losses"]
    assert log.frames().num_rows == info["samples"] > 0


def test_dropouts_warn(golden):
    with pytest.warns(wobblog.DamageWarning, match=r"dropout\.WBL: 40 frames dropped"):
        log = wobblog.open(golden["dropout"])
    assert log.damage["frames_dropped"] == 40


def test_time_jumps_warn(golden):
    with pytest.warns(wobblog.DamageWarning) as caught:
        wobblog.open(golden["timejump"])
    messages = [str(w.message) for w in caught]
    assert len(messages) == 2
    assert "time jumps forward from 0.210000 s" in messages[0]
    assert "time jumps back from 5.300000 s" in messages[1]


def test_damage_warnings_can_be_made_errors(golden):
    with warnings.catch_warnings():
        warnings.simplefilter("error", wobblog.DamageWarning)
        with pytest.raises(wobblog.DamageWarning):
            wobblog.open(golden["powercut"])


def test_missing_file_names_it(tmp_path):
    missing = tmp_path / "RUN00077.WBL"
    with pytest.raises(wobblog.WobblogError, match=r"RUN00077\.WBL: No such file"):
        wobblog.open(missing)


def test_not_a_log_names_the_file_and_cause(tmp_path):
    junk = tmp_path / "JUNK.WBL"
    junk.write_bytes(b"\x55" * 4096)
    with pytest.raises(wobblog.WobblogError,
                       match=r"JUNK\.WBL: no valid log block in 4096 bytes"):
        wobblog.open(junk)
    empty = tmp_path / "EMPTY.WBL"
    empty.write_bytes(b"")
    with pytest.raises(wobblog.WobblogError, match=r"EMPTY\.WBL: empty file"):
        wobblog.open(empty)


def test_a_directory_is_refused_as_a_log(tmp_path):
    with pytest.raises(wobblog.WobblogError, match=str(tmp_path.name)):
        wobblog.open(tmp_path)


def test_wobblog_error_is_an_exception():
    assert issubclass(wobblog.WobblogError, Exception)
    assert issubclass(wobblog.DamageWarning, UserWarning)


def test_inputs_are_never_written(golden, campaign, wobble_log):
    paths = [golden["powercut"], golden["gps"], wobble_log, campaign / "RUN00003.WBL"]
    before = [frozen(p) for p in paths]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", wobblog.DamageWarning)
        for p in paths:
            log = wobblog.open(p)
            log.frames()
            log.events()
            log.episodes()
            log.kicks()
            log.roll()
        wobblog.margin(campaign)
    assert [frozen(p) for p in paths] == before


def test_a_log_from_a_pipe_is_read_like_its_file(golden, tmp_path):
    # As the CLI: a stream (a FIFO, /dev/stdin) is copied once, then every
    # call reads the copy.
    fifo = tmp_path / "pipe.WBL"
    os.mkfifo(fifo)
    data = golden["gps"].read_bytes()

    def feed():
        with open(fifo, "wb") as f:
            f.write(data)

    writer = threading.Thread(target=feed)
    writer.start()
    piped = wobblog.open(fifo)
    writer.join()
    file = wobblog.open(golden["gps"])
    assert piped.info == file.info
    assert pa.table(piped.frames()).equals(pa.table(file.frames()))
    assert piped.events() == file.events()


def test_a_stream_opens_as_its_file_does(golden):
    path = golden["clean"]
    data = open(path, "rb").read()
    by_path = wobblog.open(path)
    streams = [io.BytesIO(data), open(path, "rb")]
    for stream in streams:
        log = wobblog.open(stream)
        assert log.info == by_path.info
        assert log.frames().to_arrow().equals(by_path.frames().to_arrow())
        # Read again after the stream is spent: the copy, not the stream.
        assert log.events() == by_path.events()
        assert str(log.path).startswith("<stream ")
    streams[1].close()
    with open(path, "rb") as named:
        assert str(wobblog.open(named).path).endswith(f": {path}>")


def test_standard_input_is_dash(golden):
    script = ("import wobblog; log = wobblog.open('-'); "
              "print(log.info['samples'], len(log.events()))")
    with open(golden["clean"], "rb") as stdin:
        out = subprocess.run([sys.executable, "-c", script], stdin=stdin,
                             capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stderr
    log = wobblog.open(golden["clean"])
    assert out.stdout.split() == [str(log.info["samples"]), str(len(log.events()))]


def test_a_stream_that_is_no_log_or_not_bytes_is_refused(golden, tmp_path):
    with pytest.raises(wobblog.WobblogError, match="binary mode"):
        with open(golden["clean"], "r", encoding="latin-1") as text:
            wobblog.open(text)
    with pytest.raises(wobblog.WobblogError, match="no valid log block"):
        wobblog.open(io.BytesIO(b"\0" * (17 << 20)))
    with pytest.raises(wobblog.WobblogError, match="<stream"):
        wobblog.open(io.BytesIO(b""))
