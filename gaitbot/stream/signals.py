"""Ctrl-C and SIGTERM (docs/bus-faults.md).

Outside a walk session (imports, planning, a recording by hand) the first two raise KeyboardInterrupt or
:class:`Terminated` in the main thread, later ones are only counted. While a session owns the bus they
only set a flag (:meth:`StopSignals.deferring`): a handler that raised in the middle of a bus exchange
would leave the exchange half done (and the SDK's port lock taken), so the session's loop looks at the
flag between exchanges, starts the safe stop, and finishes every stop ramp whatever signals follow.
"""

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
    two raise KeyboardInterrupt or Terminated, later ones are only counted (``ignored``); within
    :meth:`deferring` none raises, each is kept in ``pending`` for the session to act on."""

    def __init__(self) -> None:
        self.received = 0
        self.ignored = 0
        self.first_signal: int | None = None
        self.deferred = False
        self.pending: list[int] = []
        self._old: dict[int, object] = {}

    def handler(self, signum: int, _frame: object) -> None:
        self.received += 1
        if self.first_signal is None:
            self.first_signal = signum
        if self.deferred:
            self.pending.append(signum)
            return
        if self.received > RAISING_SIGNALS:
            self.ignored += 1
            return
        if signum == signal.SIGTERM:
            raise Terminated(f"received signal {signum}")
        raise KeyboardInterrupt

    @contextmanager
    def deferring(self):
        """Within the block signals only set the flag (``pending``); a session checks it between exchanges."""
        was = self.deferred
        self.deferred = True
        self.pending.clear()
        try:
            yield self
        finally:
            self.deferred = was

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
    return installed_stop_signals() is not None


def installed_stop_signals() -> StopSignals | None:
    """The StopSignals policy handling SIGINT and SIGTERM now, if any (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        return None
    policy = getattr(signal.getsignal(signal.SIGTERM), "__self__", None)
    if isinstance(policy, StopSignals) and getattr(signal.getsignal(signal.SIGINT), "__self__", None) is policy:
        return policy
    return None


@contextmanager
def signals_deferred():
    """Within the block SIGINT and SIGTERM only set a flag: yields the StopSignals whose ``pending`` holds
    them (the command's own policy if it installed one, else one installed for the block and then
    removed), or None off the main thread, where no handler can be set."""
    policy = installed_stop_signals()
    own = policy is None and threading.current_thread() is threading.main_thread()
    if own:
        policy = StopSignals()
        policy.install()
    if policy is None:
        yield None
        return
    try:
        with policy.deferring():
            yield policy
    finally:
        if own:
            policy.restore()


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


@contextmanager
def signals_held():
    """SIGINT and SIGTERM held back by the OS (main thread, where the platform can) while a block runs, then let
    through: a signal that interrupted an extension module's import half-way (numpy's imports run Python from C)
    can turn into an ImportError with a traceback; held, it is handled just after, where the caller expects it."""
    mask = getattr(signal, "pthread_sigmask", None)
    if mask is None or threading.current_thread() is not threading.main_thread():
        yield
        return
    held = {signal.SIGINT, signal.SIGTERM}
    mask(signal.SIG_BLOCK, held)
    try:
        yield
    finally:
        mask(signal.SIG_UNBLOCK, held)
