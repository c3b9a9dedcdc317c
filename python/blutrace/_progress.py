"""Progress reports of blutrace's long calls (``progress=`` of ``trace`` and ``optimize``).

``progress=True`` shows a tqdm bar when tqdm is installed, else one line on stderr that
is rewritten in place; a callable is called with ``(photons_done, photons_total)`` during
a trace and with each iteration's record (a dict) during an optimization.
"""

from __future__ import annotations

import sys
import time
from typing import Any, Callable, Optional


class _Callback:
    """Hands the counts (trace) or the records (optimize) to the caller's function."""

    def __init__(self, fn: Callable[..., Any], total: int) -> None:
        self.fn = fn
        self.total = total
        self.last = -1

    def update(self, done: int) -> None:
        if done != self.last:
            self.last = done
            self.fn(done, self.total)

    def close(self, done: int) -> None:
        self.update(done)

    def event(self, line: str, record: dict) -> None:
        self.fn(record)


class _Line:
    """A progress line on stderr, rewritten in place at most a few times a second."""

    def __init__(self, total: int) -> None:
        self.total = total
        self.start = time.monotonic()
        self.shown = 0.0

    def update(self, done: int) -> None:
        now = time.monotonic()
        if now - self.shown < 0.25:
            return
        self.shown = now
        rate = done / max(now - self.start, 1e-9)
        sys.stderr.write(
            f"\r{done}/{self.total} photons  {now - self.start:.1f} s  {rate:.3g} photons/s"
        )
        sys.stderr.flush()

    def close(self, done: int) -> None:
        if self.total:
            self.shown = 0.0
            self.update(done)
            sys.stderr.write("\n")
            sys.stderr.flush()

    def event(self, line: str, record: dict) -> None:
        sys.stderr.write(line + "\n")
        sys.stderr.flush()


class _Tqdm:
    """A tqdm bar of photons."""

    def __init__(self, tqdm: Any, total: int) -> None:
        self.bar = tqdm(total=total, unit="photons", unit_scale=True, leave=False)
        self.done = 0

    def update(self, done: int) -> None:
        self.bar.update(done - self.done)
        self.done = done

    def close(self, done: int) -> None:
        self.update(done)
        self.bar.close()

    def event(self, line: str, record: dict) -> None:
        self.bar.write(line)


def reporter(progress: Any, total: int) -> Optional[object]:
    """The reporter ``progress`` asks for over ``total`` photons (0: a search), or None."""
    if progress is None or progress is False:
        return None
    if progress is True:
        if total == 0:
            return _Line(0)
        try:
            from tqdm.auto import tqdm
        except ImportError:
            return _Line(total)
        return _Tqdm(tqdm, total)
    if callable(progress):
        return _Callback(progress, total)
    raise TypeError(f"progress must be True, False or a callable, not {type(progress).__name__}")
