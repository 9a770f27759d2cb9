"""SIGTERM as an exception in the main thread, so a session stops the way it does on Ctrl-C."""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager


class Terminated(BaseException):
    """Raised in the main thread by our SIGTERM handler during a walk session.

    A BaseException like KeyboardInterrupt, so that ``except Exception`` in lower layers
    cannot swallow it.
    """


def _raise_terminated(signum: int, _frame: object) -> None:
    raise Terminated(f"received signal {signum}")


_NOT_INSTALLED = object()


@contextmanager
def sigterm_raises_terminated():
    """Within the block, SIGTERM raises :class:`Terminated` in the main thread (elsewhere: no change)."""
    old_handler = install_sigterm_handler()
    try:
        yield
    finally:
        restore_sigterm_handler(old_handler)


def install_sigterm_handler() -> object:
    """Install ``_raise_terminated`` for SIGTERM; return the previous handler, or _NOT_INSTALLED."""
    if threading.current_thread() is not threading.main_thread():
        return _NOT_INSTALLED  # signal handlers can only be set from the main thread
    return signal.signal(signal.SIGTERM, _raise_terminated)


def restore_sigterm_handler(old_handler: object) -> None:
    if old_handler is _NOT_INSTALLED:
        return
    # None means the previous handler was not set from Python; the default is the best we can do.
    signal.signal(signal.SIGTERM, signal.SIG_DFL if old_handler is None else old_handler)
