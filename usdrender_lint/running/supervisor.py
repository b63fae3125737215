"""``usdrender-lint check`` and ``spec`` under a supervisor (docs/design.md, "Processes").

The process forks before any import, while it is a few megabytes: the child runs
the command and lints a lone file in its own process (a child forked from the
loaded process paid a copy of every page it touched, issue 17), and this process
waits, holding no USD. It owns the lone file's timer: the child says when that
lint starts, with its time-out, and when it ends (:meth:`Supervision.lint_started`),
and past the time-out this process kills it. When the child ran out of time or
died of a signal (USD crashed on the file), this process runs the command
itself, told how the child ended by the :class:`Supervision` it returns. Nothing
that writes the user's files is supervised: a second run could differ.

Ctrl-C reaches both processes; SIGINT or SIGTERM sent to this one alone is passed
on, and a child stuck in USD, where Python cannot run its handler, is killed
:data:`STOP_GRACE` seconds later. If this process is killed outright, Linux ends
the child (:func:`_end_with`).
"""

from __future__ import annotations

import fcntl
import os
import select
import signal
import sys
import time

from .interrupts import STOPPING, Stopped

#: The subcommands supervised, and the options after which a second run could differ.
SUPERVISED_COMMANDS = ("check", "spec")
WRITING_OPTIONS = ("--fix", "--unsafe-fixes", "--unsafe", "--diff", "--fix-to", "--write-baseline")
#: Seconds a stopped child has to clean up before it is killed.
STOP_GRACE = 2.0


class Supervision:
    """How the supervisor ran this process: handed to the command (click's context
    object), which hands it to choose_executor. (A plain class: this module is
    imported before the fork, where every import costs start-up.)"""

    __slots__ = ("child", "ending", "says")

    def __init__(
        self, child: bool = False, ending: str | None = None, says: int | None = None
    ) -> None:
        #: In the child: a lone file is linted in this process.
        self.child = child
        #: In the supervisor, after its child's "timeout" or "crash" on the lone file.
        self.ending = ending
        #: In the child: the pipe it tells the supervisor on (None: no one times it).
        self.says = says

    def lint_started(self, seconds: float | None) -> None:
        """In the child: a lint starts and may take ``seconds`` (None: no limit)."""
        self._say(seconds or 0.0)

    def lint_ended(self) -> None:
        self._say(0.0)

    def _say(self, seconds: float) -> None:
        if self.says is not None:
            try:  # noqa: SIM105 - contextlib is one more import before the fork
                os.write(self.says, b"%r\n" % seconds)
            except OSError:
                pass  # the supervisor is gone: the child ends with it (_end_with)


#: A child no supervisor times (tests run the command so).
CHILD = Supervision(child=True)


def wants_supervision(argv: list[str]) -> bool:
    """True for a ``check`` that writes nothing but its report, or a ``spec``
    (which writes its document once, after every file is read), on Linux."""
    if not sys.platform.startswith("linux") or not argv or argv[0] not in SUPERVISED_COMMANDS:
        return False  # the group has no option taking a value: its first word is the command
    return not any(arg.split("=", 1)[0] in WRITING_OPTIONS for arg in argv)


def supervise() -> Supervision:
    """Fork. In the child, return a child's :class:`Supervision` (it runs the
    command). Here, time its lone file and exit with its status, or return how
    it ended when it timed out or crashed, for this process to run the command."""
    parent = os.getpid()
    # A signal during the fork waits: the child gets Ctrl-C's own, and one sent to
    # this process is passed on once the handlers below are in place.
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, STOPPING)
    watched, held = os.pipe()  # this process holds the write end while it lives
    heard, says = os.pipe()  # the child tells this process when its lint starts and ends
    child = os.fork()
    if child == 0:
        os.close(held)
        os.close(heard)

        def close_in_workers() -> None:
            # The supervisor hears the child end, not its workers, and the
            # closing of the pipe the child watches signals no pid but the child's.
            os.close(watched)
            os.close(says)

        os.register_at_fork(after_in_child=close_in_workers)
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
        _end_with(parent, watched)
        return Supervision(child=True, says=says)
    os.close(watched)
    os.close(says)
    stopped: list[int] = []

    def pass_on(signum: int, frame: object) -> None:
        if not stopped:
            stopped.append(signum)
            signal.setitimer(signal.ITIMER_REAL, STOP_GRACE)  # then SIGALRM kills it
        _kill(child, signum)

    previous = {signum: signal.signal(signum, pass_on) for signum in STOPPING}
    previous[signal.SIGALRM] = signal.signal(signal.SIGALRM, lambda *_: _kill(child))
    signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
    try:
        timed_out = _time_the_child(child, heard)
        status = os.waitpid(child, 0)[1]  # a signal's handler runs, then Python waits on
    finally:
        # A signal from now on waits: the child's pid is free, and this process
        # either exits with the status of a run that is over or runs the command.
        signal.pthread_sigmask(signal.SIG_BLOCK, STOPPING)
        signal.setitimer(signal.ITIMER_REAL, 0)
        os.close(heard)
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    # This process imported nothing that needs cleaning up: a plain exit.
    if os.WIFEXITED(status):
        sys.exit(os.WEXITSTATUS(status))
    if stopped:  # it did not get to say it
        stop = Stopped(stopped[0])
        sys.stderr.write(f"usdrender-lint: {stop.reason}\n")
        sys.exit(stop.exit_status)
    if os.WTERMSIG(status) in STOPPING:  # a signal meant for it alone
        sys.exit(128 + os.WTERMSIG(status))
    signal.pthread_sigmask(signal.SIG_SETMASK, blocked)  # a signal that waited stops the run
    return Supervision(ending="timeout" if timed_out else "crash")


def _time_the_child(child: int, heard: int) -> bool:
    """Read what the child says until it ends (the pipe closes); True when its
    lint ran past the time-out it gave, and it was killed for it."""
    deadline: float | None = None
    while True:
        left = None if deadline is None else max(0.0, deadline - time.monotonic())
        if not select.select([heard], [], [], left)[0]:
            _kill(child)
            return True
        said = os.read(heard, 256)
        if not said:
            return False
        seconds = float(said.split()[-1])  # the latest (a lone file says twice, at most)
        deadline = time.monotonic() + seconds if seconds else None


def _kill(pid: int, signum: int = signal.SIGKILL) -> None:
    try:  # noqa: SIM105 - contextlib is one more import before the fork
        os.kill(pid, signum)
    except ProcessLookupError:
        pass  # it has just ended


def _end_with(parent: int, watched: int) -> None:
    """End this child when its supervisor ends, even by SIGKILL: Linux sends the
    owner of a pipe's read end set O_ASYNC a SIGIO, whose default action ends the
    process, when the last write end closes (fs/pipe.c, ``pipe_release``); prctl
    would need ctypes, about 1% of a one-file check's start-up."""
    fcntl.fcntl(watched, fcntl.F_SETOWN, os.getpid())
    fcntl.fcntl(watched, fcntl.F_SETFL, fcntl.fcntl(watched, fcntl.F_GETFL) | os.O_ASYNC)
    if os.getppid() != parent:  # it died before the owner was set
        os._exit(128 + signal.SIGKILL)
