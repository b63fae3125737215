"""Ctrl-C and SIGTERM: stop the run cleanly, with the shell's exit status.

The handlers raise :class:`Stopped` (a BaseException: no ``except Exception``
swallows it, and click does not turn it into "Aborted!") wherever the main process
is: the worker pool's ``finally`` then ends the workers and removes its folder, an
atomic write its temporary file, and no partial report is left. Only the first
signal raises; the next are ignored, so that a second Ctrl-C cannot cut the
clean-up short. Python runs a handler only once a hung USD call returns, and
USD's C++ may swallow the exception (while it imports a module), so the signal is
also remembered and :func:`check_stopped` raises it again at the run's next step.
"""

from __future__ import annotations

import signal  # and nothing else: the command installs the handlers before its imports

TYPE_CHECKING = False
if TYPE_CHECKING:
    from types import FrameType

#: The signals that stop a run, and what the one line on stderr says.
STOPPING = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated"}


class Stopped(BaseException):
    """The run was stopped by a signal; exit with ``128 + signal``."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum

    @property
    def exit_status(self) -> int:
        return 128 + self.signum

    @property
    def reason(self) -> str:
        return STOPPING.get(signal.Signals(self.signum), f"stopped by signal {self.signum}")


#: The signal that stopped the run, once one has.
_received: int | None = None


def _stop(signum: int, frame: FrameType | None) -> None:
    global _received
    _received = signum
    for stopping in STOPPING:
        signal.signal(stopping, signal.SIG_IGN)
    raise Stopped(signum)


def check_stopped() -> None:
    """Raise :class:`Stopped` again if a signal came and its exception was lost."""
    if _received is not None:
        raise Stopped(_received)


def install() -> None:
    """From now on, SIGINT and SIGTERM raise :class:`Stopped` (the command's first
    step, before its imports)."""
    if _received is None:
        for signum in STOPPING:
            signal.signal(signum, _stop)


class stop_on_signals:  # noqa: N801 - used as a context manager, like contextlib's
    """While the block runs, SIGINT and SIGTERM raise :class:`Stopped`."""

    def __enter__(self) -> None:
        self._previous = {signum: signal.getsignal(signum) for signum in STOPPING}
        install()

    def __exit__(self, kind: type[BaseException] | None, *rest: object) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)
        if kind is None:
            check_stopped()


class deferred:  # noqa: N801 - a context manager
    """While the block runs, SIGINT and SIGTERM wait (blocked, not lost): for USD's
    module imports, whose C++ catches the exception a handler raises in them."""

    def __enter__(self) -> None:
        self._previous = signal.pthread_sigmask(signal.SIG_BLOCK, set(STOPPING))

    def __exit__(self, *exc_info: object) -> None:
        signal.pthread_sigmask(signal.SIG_SETMASK, self._previous)


def default_signals_in_worker() -> None:
    """In a worker process: Ctrl-C is the parent's to handle (the terminal sends
    it to the whole process group); SIGTERM ends the worker at once."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
