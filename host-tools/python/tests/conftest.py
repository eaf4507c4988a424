"""Shared fixtures: the repository's logs, the `wobblog` CLI whose JSON the
package must equal, and rides encoded into logs by that CLI."""

import json
import math
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
GOLDEN = ROOT / "firmware" / "core" / "tests" / "golden"
CORPUS = ROOT / "hil-tests" / "fixtures" / "corpus"


def cli_path():
    """The CLI built from this checkout: $WOBBLOG_CLI, else the release or
    debug build in $CARGO_TARGET_DIR (or target/)."""
    if os.environ.get("WOBBLOG_CLI"):
        return Path(os.environ["WOBBLOG_CLI"])
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    for profile in ("release", "debug"):
        exe = target / profile / "wobblog"
        if exe.exists():
            return exe
    raise RuntimeError(
        f"no wobblog CLI under {target}: build it with "
        "`cargo build --release -p wobblog --bin wobblog` or set WOBBLOG_CLI")


def cli(*args):
    """Runs the CLI, which must succeed; returns its standard output."""
    out = subprocess.run([str(cli_path()), *map(str, args)],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stderr
    return out.stdout


def cli_json(*args):
    return json.loads(cli(*args))


def cli_json_lines(*args):
    return [json.loads(line) for line in cli(*args).splitlines() if line]


@pytest.fixture(scope="session")
def golden():
    """The firmware's golden logs: clean, dropout, gps, powercut, ..."""
    return {p.stem: p for p in sorted(GOLDEN.glob("*.WBL"))}


def encode(csv_text, directory, name, detect=False):
    """A log that `wobblog encode` makes of `csv_text`."""
    csv = directory / (name + ".csv")
    csv.write_text(csv_text)
    log = directory / (name + ".WBL")
    cli("encode", "--csv", csv, "-o", log, *(["--detect"] if detect else []))
    return log


# The hand-made campaign of host-tools/tests/margin_cli.rs: ring-downs
# decaying at sigma = 0.5 (u - 4), so the wobble speed is 4 m/s.
WOBBLE_MPS = 4.0
RING_HZ = 6.5
UTC0_S = 1584538100  # 2020-03-18T13:28:20Z


def kick_pass_csv(speed, seed, utc=True):
    """A 10 s pass at `speed` with one kick at 3 s, a weave and small noise,
    as CSV rows (with a `utc` column for the log's sync pairs)."""
    sigma = 0.5 * (speed - WOBBLE_MPS)
    state = (0x9E3779B9 ^ seed) & 0xFFFFFFFF
    lines = ["t_s,steer_deg,speed_mps" + (",utc" if utc else "")]
    for i in range(1000):
        t = i / 100
        state ^= (state << 13) & 0xFFFFFFFF
        state ^= state >> 17
        state ^= (state << 5) & 0xFFFFFFFF
        noise = 0.02 * (state / 0xFFFFFFFF - 0.5)
        tau = t - 3.0
        push = 4.0 * math.sin(2 * math.pi / 0.2 * tau) if 0 <= tau < 0.1 else 0.0
        ring = (1.5 * math.exp(sigma * (tau - 0.1))
                * math.sin(2 * math.pi * RING_HZ * (tau - 0.1))) if tau >= 0.1 else 0.0
        steer = 0.5 * math.sin(2 * math.pi * 0.65 * t) + push + ring + noise
        row = f"{t:.2f},{steer:.4f},{speed}"
        if utc:
            whole, frac = divmod(i, 100)
            row += f",2020-03-18T13:28:{20 + whole:02d}.{frac * 10000:06d}Z"
        lines.append(row)
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="session")
def campaign(tmp_path_factory):
    """Eight kick passes from 2.0 to 3.4 m/s, one log each, in a folder."""
    directory = tmp_path_factory.mktemp("campaign")
    for i in range(8):
        speed = 2.0 + 0.2 * i
        encode(kick_pass_csv(speed, i), directory, f"RUN{i:05d}", detect=True)
    return directory


@pytest.fixture(scope="session")
def wobble_log(tmp_path_factory):
    """The corpus ride with a 6.0 Hz wobble, as a log."""
    directory = tmp_path_factory.mktemp("wobble")
    return encode((CORPUS / "wobble_f6.0.csv").read_text(), directory, "RUN00001")


@pytest.fixture()
def damaged_copy(wobble_log, tmp_path):
    """A copy of the wobble ride with one block damaged early in it."""
    data = bytearray(wobble_log.read_bytes())
    data[20 * 512 + 77] ^= 0x10
    copy = tmp_path / "RUN00009.WBL"
    copy.write_bytes(bytes(data))
    return copy


def frozen(path):
    """A file's bytes and modification time, to show it was left as it was."""
    return path.read_bytes(), path.stat().st_mtime_ns

