"""The GIL is released while tracing, and Ctrl-C (a real SIGINT) stops a trace or a search."""

from __future__ import annotations

import os
import signal
import threading
import time

import pytest

import blutrace as bt


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


def interrupted_after(seconds: float, call) -> float:
    """Send this process a real SIGINT after `seconds` while `call()` runs; assert that it
    raises KeyboardInterrupt and return how long after the signal it stopped."""
    assert threading.current_thread() is threading.main_thread()
    # Python's own Ctrl-C handler, even where the test runner was started with SIGINT
    # ignored (a background job of a shell).
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(seconds, lambda: os.kill(os.getpid(), signal.SIGINT))
    try:
        start = time.monotonic()
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            call()
        return time.monotonic() - start - seconds
    finally:
        timer.join()
        signal.signal(signal.SIGINT, previous)


@pytest.mark.skipif(not hasattr(signal, "SIGINT"), reason="no SIGINT")
def test_sigint_stops_a_trace_within_a_second_and_raises(box, tmp_path):
    # Far more photons than 0.5 s can trace; max_time bounds a failing test.
    late = interrupted_after(0.5, lambda: box.trace(photons=1e9, max_time=60, seed=1))
    assert late < 1.5, f"took {late:.2f} s to stop"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not hasattr(signal, "SIGINT"), reason="no SIGINT")
def test_sigint_before_an_optimizations_first_design_raises(phone):
    late = interrupted_after(
        0.5, lambda: phone.optimize(method="feedback", photons=2e7, max_iter=3, verify_photons=0)
    )
    assert late < 1.5, f"took {late:.2f} s to stop"


@pytest.mark.skipif(not hasattr(signal, "SIGINT"), reason="no SIGINT")
@pytest.mark.parametrize(
    "search",
    [
        {"method": "feedback", "max_iter": 10_000},
        {"method": "grid", "vary": {"sources.*.center.2": (0.2, 0.35)}, "grid_points": 10_000,
         "objective": "efficiency"},
    ],
    ids=["density", "vary"],
)
def test_sigint_during_an_optimization_returns_the_designs_traced(phone, tmp_path, search):
    """Ctrl-C once a design is traced: the search stops and returns what it found, as
    `blutrace optimize` writes its set (10,000 iterations would take hours)."""
    heard = []
    first, returned = threading.Event(), threading.Event()

    def record(r):
        heard.append(r)
        first.set()

    def ctrl_c():
        if first.wait(120) and not returned.is_set():
            os.kill(os.getpid(), signal.SIGINT)

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    killer = threading.Thread(target=ctrl_c)
    try:
        killer.start()
        start = time.monotonic()
        try:
            opt = phone.optimize(photons=20_000, verify_photons=1e8, progress=record, **search)
        except KeyboardInterrupt:
            pytest.fail("Ctrl-C raised instead of returning the designs traced")
        elapsed = time.monotonic() - start
    finally:
        returned.set()
        first.set()
        killer.join()
        signal.signal(signal.SIGINT, previous)
    assert opt.interrupted is True and opt.summary["interrupted"] is True
    assert elapsed < 60, f"took {elapsed:.1f} s"
    assert 1 <= len(opt.history) <= len(heard)
    assert opt.summary["verification"] is None  # 1e8 verification photons: dropped
    files = {p.split("/")[-1] for p in opt.write(tmp_path / "opt")}
    assert {"optimized.toml", "history.csv", "optimize.json"} <= files
    assert bt.Scene.load(tmp_path / "opt" / "optimized.toml").content_hash == opt.scene.content_hash


def test_an_exception_of_the_progress_callable_stops_the_trace(box):
    def fail(done, total):
        if done:
            raise RuntimeError("stop here")

    start = time.monotonic()
    with pytest.raises(RuntimeError, match="stop here"):
        box.trace(photons=1e9, max_time=60, seed=1, progress=fail)
    assert time.monotonic() - start < 5
