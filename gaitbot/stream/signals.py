"""SIGTERM as an exception in the main thread, so a session stops the way it does on Ctrl-C; and what
repeated signals do (docs/bus-faults.md): the first Ctrl-C or SIGTERM starts the safe stop, the second
forces the stop without the ramp, later ones are ignored while gaitbot switches torque off (if
configured), closes the port and reports."""

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

#: Signals that raise: the first starts the safe stop, the second abandons it. Later ones are ignored.
RAISING_SIGNALS = 2


class StopSignals:
    """SIGINT and SIGTERM for a whole command (``install``/``restore`` from the main thread): the first
    two raise KeyboardInterrupt or Terminated, later ones are only counted (``ignored``)."""

    def __init__(self) -> None:
        self.received = 0
        self.ignored = 0
        self.first_signal: int | None = None
        self._old: dict[int, object] = {}

    def handler(self, signum: int, _frame: object) -> None:
        self.received += 1
        if self.first_signal is None:
            self.first_signal = signum
        if self.received > RAISING_SIGNALS:
            self.ignored += 1
            return
        if signum == signal.SIGTERM:
            raise Terminated(f"received signal {signum}")
        raise KeyboardInterrupt

    def install(self) -> bool:
        if threading.current_thread() is not threading.main_thread():
            return False
        for signum in (signal.SIGINT, signal.SIGTERM):
            self._old[signum] = signal.signal(signum, self.handler)
        return True

    def ignore_from_now(self) -> None:
        """After a command that was signalled: further signals are ignored while the process exits (the
        user's Ctrl-C already decided how it ends; a late one must not turn into a traceback)."""
        if threading.current_thread() is threading.main_thread():
            for signum in (signal.SIGINT, signal.SIGTERM):
                signal.signal(signum, signal.SIG_IGN)
        self._old.clear()

    def restore(self) -> None:
        for signum, old in self._old.items():
            signal.signal(signum, signal.SIG_DFL if old is None else old)
        self._old.clear()


def stop_signals_installed() -> bool:
    """True when a StopSignals policy handles SIGTERM now (a command installed it for its whole run)."""
    if threading.current_thread() is not threading.main_thread():
        return False
    handler = signal.getsignal(signal.SIGTERM)
    return isinstance(getattr(handler, "__self__", None), StopSignals)


@contextmanager
def sigterm_raises_terminated():
    """Within the block, SIGTERM raises :class:`Terminated` in the main thread (elsewhere: no change)."""
    old_handler = install_sigterm_handler()
    try:
        yield
    finally:
        restore_sigterm_handler(old_handler)


def install_sigterm_handler() -> object:
    """Install ``_raise_terminated`` for SIGTERM; return the previous handler, or _NOT_INSTALLED (also
    when a command's StopSignals policy already handles it: that policy stays)."""
    if threading.current_thread() is not threading.main_thread() or stop_signals_installed():
        return _NOT_INSTALLED  # signal handlers can only be set from the main thread
    return signal.signal(signal.SIGTERM, _raise_terminated)


def restore_sigterm_handler(old_handler: object) -> None:
    if old_handler is _NOT_INSTALLED:
        return
    # None means the previous handler was not set from Python; the default is the best we can do.
    signal.signal(signal.SIGTERM, signal.SIG_DFL if old_handler is None else old_handler)
