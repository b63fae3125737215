"""``usdrender-lint check`` and ``spec``: a small process watches while its child runs the command.

A file that crashes USD or never finishes must cost that file, not the report
(issue 13). A check of one file used to get that by forking a child of the
loaded process to lint it; the child then paid a copy of every page of the
100 MB it touched: its lint took about 25 ms more than in-process (issue 17). Here the fork
happens first, before any import, when the process is a few megabytes: the
child runs the whole command and lints a lone file in-process, and this
process, which imports nothing more, waits for it.

- The child exits: this process exits with its status (it printed the report).
- It runs past ``--timeout`` on its lone file: this process owns the timer.
  The child says when that file's lint starts and ends over a pipe
  (:func:`lint_started`, :func:`lint_ended`); past the time-out this process
  kills it.
- It dies of another signal: USD crashed on the file.

In the last two cases this process runs the command itself, with a
:class:`Supervision` saying how the child ended (the executor's input,
workers.AfterSupervisedChild): it reports the time-out without linting
again, or lints the file in a worker with the whole stage composed, the
retry the pool gives any file a worker died on. Nothing is supervised where a second
run could differ from the first: ``--fix``, ``--diff``, ``--fix-to`` and
``--write-baseline`` write to the user's files.

Signals: Ctrl-C reaches both processes (the terminal signals the process
group); SIGINT or SIGTERM sent to this process alone is passed on. The child
handles it (one line, exit 130 or 143); a child stuck in USD, where Python
cannot run the handler, is killed after :data:`STOP_GRACE` seconds and this
process says the line. If this process is killed outright, Linux ends the
child (a SIGIO from the pipe it watches, see :func:`_end_with`).
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
    """How the supervisor ran this process: handed to the command (click's
    context object), which passes it to the executor it chooses. (A plain
    class: this module is imported before the fork, where every import is
    paid by the command's start-up.)"""

    __slots__ = ("child", "ending", "says")

    def __init__(
        self, child: bool = False, ending: str | None = None, says: int | None = None
    ) -> None:
        #: In the child: a lone file is linted in this process, under the time-out.
        self.child = child
        #: In the supervisor after its child ran out of time ("timeout") or
        #: crashed ("crash"): the command runs here, knowing that of the file.
        self.ending = ending
        #: In the child: the pipe on which it tells the supervisor when its
        #: lone file's lint starts and ends (None: no supervisor times it).
        self.says = says

    def __repr__(self) -> str:
        return f"Supervision(child={self.child}, ending={self.ending!r}, says={self.says})"


#: A child no supervisor times (tests run the command so).
CHILD = Supervision(child=True)

_child = 0
_stop_signal: int | None = None
#: In the supervised child: the read end of the pipe it watches (_end_with),
#: and the write end of the one it tells its supervisor on (Supervision.says).
_watched: int | None = None
_says: int | None = None


def wants_supervision(argv: list[str]) -> bool:
    """True for a ``check`` that writes nothing but its report, or a ``spec``
    (which writes its document once, after every file is read), on Linux."""
    if not sys.platform.startswith("linux") or not hasattr(os, "fork"):
        return False
    # The group has no option taking a value: its first word is the command.
    if not argv or argv[0] not in SUPERVISED_COMMANDS:
        return False
    return not any(arg.split("=", 1)[0] in WRITING_OPTIONS for arg in argv)


def supervise() -> Supervision:
    """Fork. In the child, return a child's :class:`Supervision` (it runs the
    command). Here, wait and time its lone file: exit with the child's status,
    or return how it ended when it timed out or crashed, for this process to
    run the command itself."""
    global _child, _says
    parent = os.getpid()
    # A signal during the fork waits: the child gets Ctrl-C's own, and one sent
    # to this process is passed on once the handlers below are in place.
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, STOPPING)
    # This process holds the write end for as long as it lives (see _end_with).
    watched, held = os.pipe()
    # The child tells this process when its lone file's lint starts and ends.
    heard, says = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(held)
        os.close(heard)
        _says = says
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
        _end_with(parent, watched)
        return Supervision(child=True, says=says)
    os.close(watched)
    os.close(says)
    _child = pid
    previous = {signum: signal.signal(signum, _pass_on) for signum in STOPPING}
    previous[signal.SIGALRM] = signal.signal(signal.SIGALRM, _kill_child)
    signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
    try:
        timed_out = _time_the_child(heard)
        status = _wait(pid)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    # This process imported nothing that needs cleaning up: a plain exit.
    if _stop_signal is not None:
        if os.WIFSIGNALED(status):  # it did not get to say it
            stopped = Stopped(_stop_signal)
            sys.stderr.write(f"usdrender-lint: {stopped.reason}\n")
            sys.exit(stopped.exit_status)
        sys.exit(os.waitstatus_to_exitcode(status))
    if timed_out:
        return Supervision(ending="timeout")
    if os.WIFEXITED(status):
        sys.exit(os.WEXITSTATUS(status))
    died = os.WTERMSIG(status)
    if died in STOPPING:  # stopped by a signal meant for it alone
        sys.exit(128 + died)
    return Supervision(ending="crash")


def _time_the_child(heard: int) -> bool:
    """Read what the child says until it ends (the pipe closes); True when its
    lone file ran past the time-out it gave, and it was killed for it."""
    deadline: float | None = None
    pending = b""
    while True:
        left = None if deadline is None else max(0.0, deadline - time.monotonic())
        if not select.select([heard], [], [], left)[0]:  # past the file's time-out
            _kill_child(signal.SIGKILL, None)
            os.close(heard)
            return _stop_signal is None
        said = os.read(heard, 256)
        if not said:
            os.close(heard)
            return False
        *lines, pending = (pending + said).split(b"\n")
        for line in lines:
            # "S<seconds>": a lint started (0: no limit); "E": it ended.
            seconds = float(line[1:]) if line.startswith(b"S") else 0.0
            deadline = time.monotonic() + seconds if seconds else None


def lint_started(supervision: Supervision, seconds: float | None) -> None:
    """In the child: the lone file's lint starts, and may take ``seconds``."""
    _say(supervision, b"S%r\n" % float(seconds or 0))


def lint_ended(supervision: Supervision) -> None:
    _say(supervision, b"E\n")


def _say(supervision: Supervision, line: bytes) -> None:
    if supervision.says is None:
        return
    try:  # noqa: SIM105 - contextlib is one more import before the fork
        os.write(supervision.says, line)
    except OSError:
        pass  # the supervisor is gone: the child ends with it (_end_with)


def _wait(pid: int) -> int:
    try:
        return os.waitpid(pid, 0)[1]  # a signal's handler runs, then Python waits on
    except ChildProcessError:
        return 0


def _pass_on(signum: int, frame: object) -> None:
    global _stop_signal
    if _stop_signal is None:
        _stop_signal = signum
        signal.setitimer(signal.ITIMER_REAL, STOP_GRACE)
    try:
        os.kill(_child, signum)
    except ProcessLookupError:
        return  # it has just ended


def _kill_child(signum: int, frame: object) -> None:
    try:
        os.kill(_child, signal.SIGKILL)
    except ProcessLookupError:
        return


def _end_with(parent: int, watched: int) -> None:
    """End this child when its supervisor ends, even by SIGKILL: Linux sends
    the owner of a pipe's read end set O_ASYNC a SIGIO, whose default action
    ends the process, when the last write end closes (fs/pipe.c,
    ``pipe_release``). It does what :func:`die_with_parent` does without
    importing ctypes, about 1% of a one-file check's start-up."""
    global _watched
    _watched = watched
    fcntl.fcntl(watched, fcntl.F_SETOWN, os.getpid())
    fcntl.fcntl(watched, fcntl.F_SETFL, fcntl.fcntl(watched, fcntl.F_GETFL) | os.O_ASYNC)
    if os.getppid() != parent:  # it died before the owner was set
        os._exit(128 + signal.SIGKILL)


def die_with_parent(parent: int) -> None:
    """Have Linux kill this process when its parent (pid ``parent``) dies, even
    by SIGKILL (``prctl(PR_SET_PDEATHSIG)``); elsewhere the parent's clean-up
    must do. A parent already gone ends this process now."""
    if not sys.platform.startswith("linux"):
        return
    global _watched, _says
    if _watched is not None:
        # Forked from the supervised child: the pipe it watches must close with
        # it. Held on here, it would signal the child's pid once the child is
        # gone, a pid Linux may have given to another process by then.
        os.close(_watched)
        _watched = None
    if _says is not None:
        os.close(_says)  # the supervisor hears the end of the child, not of its workers
        _says = None
    import ctypes

    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # 1: PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:  # it died before the call took effect
        os.kill(os.getpid(), signal.SIGKILL)


__all__ = [
    "CHILD",
    "Supervision",
    "die_with_parent",
    "lint_ended",
    "lint_started",
    "supervise",
    "wants_supervision",
]
