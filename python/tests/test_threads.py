"""The GIL is released while tracing, and Ctrl-C (a real SIGINT) stops a trace."""

from __future__ import annotations

import os
import signal
import threading
import time

import pytest


def test_other_python_threads_run_during_a_trace(box):
    counts = [0]
    stop = threading.Event()

    def count():
        while not stop.is_set():
            counts[0] += 1

    t = threading.Thread(target=count)
    t.start()
    try:
        time.sleep(0.05)
        before = counts[0]
        start = time.monotonic()
        box.trace(photons=1e9, max_time=0.5, seed=1)
        during = counts[0] - before
        elapsed = time.monotonic() - start
    finally:
        stop.set()
        t.join()
    assert elapsed >= 0.5
    # A thread starved by a held GIL counts nothing at all; a free one counts millions.
    assert during > 10_000, f"the counting thread counted {during} in {elapsed:.2f} s"


@pytest.mark.skipif(not hasattr(signal, "SIGINT"), reason="no SIGINT")
def test_sigint_stops_a_trace_within_a_second_and_raises(box, tmp_path):
    assert threading.current_thread() is threading.main_thread()
    # Python's own Ctrl-C handler, even where the test runner was started with SIGINT
    # ignored (a background job of a shell).
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    try:
        start = time.monotonic()
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            # Far more photons than 0.5 s can trace; max_time bounds a failing test.
            box.trace(photons=1e9, max_time=60, seed=1)
        stopped = time.monotonic() - start
    finally:
        timer.join()
        signal.signal(signal.SIGINT, previous)
    assert stopped < 0.5 + 1.5, f"took {stopped:.2f} s to stop"
    assert list(tmp_path.iterdir()) == []
