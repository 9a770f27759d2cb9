"""Progress bars and live status lines for long work, on stderr, only when stderr is a terminal.

Built on tqdm: it draws at most ten times a second whatever the update rate and runs no drawing
thread, so a bar costs the 60 Hz walk loop next to nothing (its monitor thread is switched off
below). When stderr is not a terminal (a pipe, a file, CI, the tests) every bar is a no-op and
nothing is printed: output meant for people must not end up in logs.
"""

from __future__ import annotations

import os
import sys
from contextlib import contextmanager

from tqdm import tqdm

tqdm.monitor_interval = 0  # no monitor thread next to a real-time loop


def on_terminal() -> bool:
    return sys.stderr.isatty()


class _Silent:
    """What a bar is when nobody is watching."""

    n = 0
    total = None

    def update(self, n: int = 1) -> None:
        pass

    def reset(self, total: int | None = None) -> None:
        pass

    def set_postfix_str(self, text: str, refresh: bool = True) -> None:
        pass

    def set_description_str(self, text: str, refresh: bool = True) -> None:
        pass

    def close(self) -> None:
        pass


def _size() -> tuple[int, int]:
    """The terminal's columns and lines; one that reports no size (a fresh pseudo-terminal, some serial consoles)
    gets 100 x 24, since tqdm would otherwise draw nothing at all (a bar 0 wide, on row -1)."""
    try:
        size = os.get_terminal_size(sys.stderr.fileno())
        return size.columns or 100, size.lines or 24
    except (OSError, ValueError):
        return 100, 24


@contextmanager
def progress(what: str, total: int | None = None, unit: str = "it", leave: bool = False):
    """A bar for ``total`` pieces of work (or a counter if None); ``update(n)`` as pieces are done.

    Closed (and, with ``leave=False``, erased) at the end, so what follows starts on a clean line."""
    if not on_terminal():
        yield _Silent()
        return
    columns, lines = _size()
    bar = tqdm(total=total, desc=what, unit=unit, leave=leave, file=sys.stderr, ncols=columns, nrows=lines,
               mininterval=0.1)
    try:
        yield bar
    finally:
        bar.close()


def callback(bar):
    """``done(k, n)`` for rooms that report progress as "k of n done" (they import nothing of the app)."""

    def done(k: int, n: int) -> None:
        if bar.total != n:
            bar.reset(total=n)
        bar.update(k - bar.n)

    return done
