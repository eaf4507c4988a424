"""Ctrl-C stops a long decoding: `open()`, which decodes the log's summary and
frames in one pass, looks for a pending KeyboardInterrupt while it works
without the GIL, instead of finishing first."""

import _thread
import signal
import threading
import time

import pytest

import wobblog
from conftest import encode


@pytest.fixture(scope="module")
def long_log(tmp_path_factory):
    """A 40-minute ride (240 000 frames)."""
    lines = ["t_s,steer_deg,speed_mps"]
    lines.extend(f"{i / 100:.2f},{(i % 200) / 100:.2f},4.0" for i in range(240_000))
    return encode("\n".join(lines) + "\n", tmp_path_factory.mktemp("long"), "RUN00001")


@pytest.fixture
def ctrl_c_raises():
    """Python's own SIGINT handler for the test: a process started in the
    background by a non-interactive shell inherits SIGINT ignored, and then
    Python installs no handler and `interrupt_main` does nothing."""
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, before)


def test_ctrl_c_stops_open_before_it_ends(long_log, ctrl_c_raises):
    start = time.perf_counter()
    whole = wobblog.open(long_log).frames()
    uninterrupted = time.perf_counter() - start
    assert whole.num_rows == 240_000
    # Ctrl-C a tenth of the way in, from another thread (the GIL is free).
    timer = threading.Timer(uninterrupted / 10, _thread.interrupt_main)
    start = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        wobblog.open(long_log)
        # Not reached when the decoding stopped; Python would raise the
        # interrupt here otherwise, after the whole decoding.
        time.sleep(1.0)
    interrupted = time.perf_counter() - start
    timer.join()
    assert interrupted < 0.7 * uninterrupted, (interrupted, uninterrupted)
