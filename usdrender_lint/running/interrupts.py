"""Ctrl-C and SIGTERM: stop the run cleanly, with the shell's exit status.

The handlers raise :class:`Stopped` (a BaseException, so no ``except
Exception`` swallows it and click does not turn it into "Aborted!") wherever
the main process is: the worker pool's ``finally`` then kills the workers and
removes its temporary folder, an atomic write removes its temporary file, and
no partial report is left behind. Only the first signal raises: the next ones
are ignored, so a second Ctrl-C cannot cut the clean-up short. A hung USD call
in this process (``--jobs 1 --timeout 0``) cannot be interrupted: Python runs
the handler only when the call returns.
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager
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


def _stop(signum: int, frame: FrameType | None) -> None:
    for stopping in STOPPING:
        signal.signal(stopping, signal.SIG_IGN)
    raise Stopped(signum)


@contextmanager
def stop_on_signals() -> Iterator[None]:
    """While the block runs, SIGINT and SIGTERM raise :class:`Stopped`."""
    previous = {signum: signal.signal(signum, _stop) for signum in STOPPING}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def default_signals_in_worker() -> None:
    """In a worker process: Ctrl-C is the parent's to handle (the terminal
    sends it to the whole process group), SIGTERM ends the worker at once."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
