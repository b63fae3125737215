"""Ctrl-C and SIGTERM stop the run cleanly, with the shell's exit status: the handler
raises :class:`Stopped` (a BaseException, which neither ``except Exception`` nor click
swallows) wherever the process is, so that the pool's ``finally`` ends its workers and
an atomic write removes its temporary file. Later signals are ignored (a second Ctrl-C
cannot cut the clean-up short). USD's C++ may swallow the exception, and Python runs
the handler only once a USD call returns: :func:`check_stopped` raises it again.
"""

from __future__ import annotations

import signal  # and nothing else: the command installs the handlers before its imports
import sys

#: SIGHUP too: a closed terminal or SSH session ends the run as SIGTERM does, its
#: workers' temporary folder removed (by default it ended the process where it was).
STOPPING = {
    signal.SIGINT: "interrupted",
    signal.SIGTERM: "terminated",
    signal.SIGHUP: "hung up",
}
#: Asks a timed lint for its Python stack before it is killed (running/stalls.py);
#: SIGUSR1 stays the user's (it ends the process).
STALL_SIGNAL = signal.SIGUSR2


class Stopped(BaseException):
    """The run was stopped by SIGINT or SIGTERM: say ``reason``, exit ``128 + signal``."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.exit_status = 128 + signum
        self.reason = STOPPING[signal.Signals(signum)]


_received: int | None = None
#: How many times the process was continued after a stop (Ctrl-Z, then ``fg``):
#: the time it stood still was no file's (workers.Pool times its files again).
_continued = 0


def _stop(signum: int, frame: object) -> None:
    global _received
    _received = signum
    for stopping in STOPPING:
        signal.signal(stopping, signal.SIG_IGN)
    raise Stopped(signum)


def _count_continue(signum: int, frame: object) -> None:
    global _continued
    _continued += 1


def continued() -> int:
    """How many times the process was continued after a stop (SIGCONT)."""
    return _continued


def check_stopped() -> None:
    """Raise :class:`Stopped` again if a signal came and its exception was lost."""
    if _received is not None:
        raise Stopped(_received)


def install() -> None:
    """From now on SIGINT and SIGTERM raise :class:`Stopped` (before the imports),
    unless the process was started ignoring them (not_ignored)."""
    if _received is None:
        for signum in not_ignored():
            signal.signal(signum, _stop)
        sys.unraisablehook = _quiet_when_stopped
        if hasattr(signal, "SIGCONT"):  # the process still continues, as by default
            signal.signal(signal.SIGCONT, _count_continue)


def not_ignored() -> list[int]:
    """The signals of STOPPING this process does not ignore. One started with
    SIGINT ignored (a script's background job ``lint &``, ``trap '' INT``) is to
    outlive the Ctrl-C that stops its foreground job, as sleep and Python's own
    default handler leave it (it was stopped with exit 130)."""
    return [signum for signum in STOPPING if signal.getsignal(signum) is not signal.SIG_IGN]


def _quiet_when_stopped(unraisable: sys.UnraisableHookArgs, say=sys.unraisablehook) -> None:
    # A signal in an import can land in importlib's weakref callback, where Python
    # prints it instead of raising it: check_stopped raises it later, without a traceback.
    if not isinstance(unraisable.exc_value, Stopped):
        say(unraisable)


class stop_on_signals:  # noqa: N801 - used as a context manager, like contextlib's
    """While the block runs, SIGINT and SIGTERM raise :class:`Stopped`."""

    def __enter__(self) -> None:
        self._previous = {signum: signal.getsignal(signum) for signum in STOPPING}
        install()

    def __exit__(self, kind: type[BaseException] | None, *rest: object) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)
        # click ends every command with sys.exit: a signal whose exception USD
        # swallowed is the run's status still, not a quiet exit 0.
        if kind is None or issubclass(kind, SystemExit):
            check_stopped()


class deferred:  # noqa: N801 - a context manager
    """SIGINT and SIGTERM wait (blocked) until the block ends: USD's imports catch it."""

    def __enter__(self) -> None:
        self._previous = signal.pthread_sigmask(signal.SIG_BLOCK, set(STOPPING))

    def __exit__(self, *exc_info: object) -> None:
        signal.pthread_sigmask(signal.SIG_SETMASK, self._previous)
