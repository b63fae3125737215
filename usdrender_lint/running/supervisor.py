"""``check`` and ``spec`` fork before any import, while the process is a few megabytes:
the child runs the command and lints a lone file in-process (a child forked from the
loaded process copied every page it touched, issue 17); this process holds no USD,
owns that lint's timer (:meth:`Supervision.timed`), and runs the command itself with
how the child ended when it timed out or crashed. Nothing that writes the user's
files is supervised (a second run could differ). Signals: docs/design.md, "Processes".
"""

from __future__ import annotations

import atexit
import fcntl
import os
import select
import signal
import sys
import time

from .interrupts import STALL_SIGNAL, STOPPING, Stopped, continued, not_ignored

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

SUPERVISED_COMMANDS = ("check", "spec")
WRITING_OPTIONS = ("--fix", "--unsafe-fixes", "--unsafe", "--diff", "--fix-to", "--write-baseline")
#: What fixes standard input's text (``check --fix -``) writes: stdout alone.
STDOUT_FIXES = ("--fix", "--unsafe-fixes", "--unsafe", "--diff")
#: The options of ``check`` and ``spec`` that take a value, the next word unless
#: given as ``--opt=value`` (tests/cli/test_supervisor.py checks them against the
#: commands'): a value such as ``--output -`` is not a path, and ``-`` not stdin.
VALUE_OPTIONS = frozenset(
    (
        *("--baseline", "--cache-dir", "--config", "--exclude", "--extend-exclude"),
        *("--extend-select", "--fail-on", "--fix-to", "--format", "--ignore", "--jobs", "-j"),
        *("--max-variant-combinations", "--output", "--profile", "--select", "--settings"),
        *("--shard", "--stdin-filename", "--time", "--timeout", "--write-baseline"),
    )
)
STOP_GRACE = 2.0  # seconds a stopped child has to clean up before it is killed
STACK_WAIT = 0.5  # seconds a timed-out child has to write its stack (stalls.py)
DONE = b"done"  # what the child says as Python exits


class Supervision:
    """How the supervisor ran this process, for choose_executor; ``ending`` is None in
    the child, which lints a lone file in-process (a plain class: every import before
    the fork costs start-up). ``stdin``: standard input's bytes for ``check -``, read
    before the fork, so that the supervisor still holds them after the child's end."""

    __slots__ = ("ending", "says", "stall", "stdin")

    def __init__(
        self,
        ending: str | None = None,
        says: int | None = None,
        stdin: bytes | None = None,
        stall: str | None = None,
    ) -> None:
        self.ending = ending  # in the supervisor: the child's "timeout" or "crash"
        self.says = says  # in the child: the pipe to its supervisor (None: untimed)
        self.stdin = stdin
        self.stall = stall  # in the supervisor: the child's stack as it timed out

    def timed(self, seconds: float, lint: Any, *args: Any) -> Any:
        """In the child: ``lint(*args)``, killed by the supervisor past ``seconds``."""
        self._say(seconds)
        try:
            return lint(*args)
        finally:
            self._say(0.0)

    def _say(self, seconds: float) -> None:
        self._tell(b"%r\n" % seconds)

    def _tell(self, message: bytes) -> None:
        if self.says is not None:
            try:  # noqa: SIM105 - contextlib is one more import before the fork
                os.write(self.says, message)
            except OSError:
                pass  # the supervisor is gone: the child ends with it (SIGIO)

    def exiting(self) -> None:
        """In the child, as Python exits (atexit): its exit status is the command's.
        A child that ends without saying so was ended under the command (a rule's
        os._exit(0) in a lone file's lint): its status means nothing."""
        self._tell(DONE + b"\n")


def open_closed_standard_fds() -> None:
    """Put /dev/null on a standard file descriptor that was closed when the
    command started (``check 2>&-``): else the next file or pipe opened gets the
    number (the supervisor's pipe was the child's fd 2), and whatever USD or the
    command prints lands in it. Before the fork: the child inherits them."""
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            null = os.open(os.devnull, os.O_RDWR)
            if null != fd:
                os.dup2(null, fd)
                os.close(null)


def wants_supervision(argv: list[str]) -> bool:
    """A ``check`` that writes nothing but its report (``check --fix -``: and the
    fixed text, to stdout), or a ``spec``, on Linux; not ``check --watch``."""
    if not sys.platform.startswith("linux") or not argv or argv[0] not in SUPERVISED_COMMANDS:
        return False  # the group has no option taking a value: its first word is the command
    if "--watch" in argv:
        return False  # it runs until stopped: each round's workers time their files
    paths, options = parse_arguments(argv[1:])
    writing = options & set(WRITING_OPTIONS)
    if lints_standard_input(paths, options):  # its fixes write nothing but stdout
        writing -= set(STDOUT_FIXES)
    return not writing


def reads_standard_input(argv: list[str]) -> bool:
    """``check -`` (a layer's text on standard input), when it is not a terminal
    (the command says so, with no wait for a text that will not come)."""
    return (
        argv[:1] == ["check"]
        and lints_standard_input(*parse_arguments(argv[1:]))
        and (not os.isatty(0))
    )


def lints_standard_input(paths: list[str], options: set[str]) -> bool:
    """Whether a ``check`` of these paths and options lints standard input's text:
    ``-`` alone, or no path with ``--stdin-filename`` (as ruff reads it then)."""
    return paths == ["-"] or (not paths and "--stdin-filename" in options)


def parse_arguments(words: list[str]) -> tuple[list[str], set[str]]:
    """The paths and the option names among a command's words, as click tells
    them apart: an option in VALUE_OPTIONS takes the next word, and ``--`` ends
    the options."""
    paths: list[str] = []
    options: set[str] = set()
    rest = iter(words)
    for word in rest:
        if word == "--":
            paths.extend(rest)
        elif word.startswith("-") and word != "-":
            name, given, _ = word.partition("=")
            options.add(name)
            if name in VALUE_OPTIONS and not given:
                next(rest, None)
        else:
            paths.append(word)
    return paths, options


def _read_all(fd: int) -> bytes:
    chunks = []
    try:
        while chunk := os.read(fd, 1 << 20):
            chunks.append(chunk)
    except OSError:
        pass  # closed or unreadable: the text ends there
    return b"".join(chunks)


def supervise(stdin: bool = False) -> Supervision:
    """Fork: the child returns (and runs the command); this process exits with its
    status, or returns how it ended when it timed out or crashed. ``stdin``: read
    standard input first (reads_standard_input), for both."""
    data = _read_all(0) if stdin else None
    parent = os.getpid()
    # A signal during the fork waits: the child gets Ctrl-C's own; one sent here alone
    # is passed on once the handlers below are in place.
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, STOPPING)
    watched, held = os.pipe()  # this process holds the write end while it lives
    heard, says = os.pipe()  # the child tells this process when its lint starts and ends
    stack_read, stack_write = os.pipe()  # the child's stack, asked for as it times out
    child = os.fork()
    if child == 0:
        os.close(held)
        os.close(heard)
        os.close(stack_read)
        import faulthandler  # built in: no search on the path

        faulthandler.register(STALL_SIGNAL, file=stack_write, all_threads=True)
        supervision = Supervision(says=says, stdin=data)
        # Before a signal can stop it: a child stopped by one says it exits too.
        atexit.register(supervision.exiting)

        def close_in_workers() -> None:
            # This process hears the child end, not its workers; the pipe the child
            # watches signals no pid but the child's.
            atexit.unregister(supervision.exiting)
            faulthandler.unregister(STALL_SIGNAL)  # a worker writes its stack to its log
            os.close(watched)
            os.close(says)
            os.close(stack_write)

        os.register_at_fork(after_in_child=close_in_workers)
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
        # End with this process, even by SIGKILL: the last write end of a pipe closing
        # sends its O_ASYNC reader's owner a SIGIO (fs/pipe.c), which ends it (prctl
        # needs ctypes: 8M instructions, 0.6% of a one-file check's start-up).
        fcntl.fcntl(watched, fcntl.F_SETOWN, os.getpid())
        fcntl.fcntl(watched, fcntl.F_SETFL, fcntl.fcntl(watched, fcntl.F_GETFL) | os.O_ASYNC)
        if os.getppid() != parent:  # it died before the owner was set
            os._exit(128 + signal.SIGKILL)
        return supervision
    os.close(watched)
    os.close(says)
    os.close(stack_write)
    stopped: list[int] = []

    def pass_on(signum: int, frame: object) -> None:
        if not stopped:
            stopped.append(signum)
            signal.setitimer(signal.ITIMER_REAL, STOP_GRACE)  # then SIGALRM kills it
        _kill(child, signum)

    previous = {signum: signal.signal(signum, pass_on) for signum in not_ignored()}
    previous[signal.SIGALRM] = signal.signal(signal.SIGALRM, lambda *_: _kill(child))
    signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
    heard_end = _time_the_child(child, heard, stack_read)
    status = os.waitpid(child, 0)[1]  # a signal's handler runs, then Python waits on
    # A signal from now on waits: the child's pid is free, and this process exits
    # with the status of a finished run, or runs the command (then it stops it).
    signal.pthread_sigmask(signal.SIG_BLOCK, STOPPING)
    signal.setitimer(signal.ITIMER_REAL, 0)
    os.close(heard)
    stall = _read_stack(stack_read) if heard_end == "timeout" else None
    os.close(stack_read)
    for signum, handler in previous.items():
        signal.signal(signum, handler)
    # This process imported nothing that needs cleaning up: a plain exit.
    if os.WIFEXITED(status) and heard_end == "done":
        sys.exit(os.WEXITSTATUS(status))
    if stopped or os.WTERMSIG(status) in STOPPING:  # it did not get to say it
        stop = Stopped(stopped[0] if stopped else os.WTERMSIG(status))
        sys.stderr.write(f"usdrender-lint: {stop.reason}\n")
        sys.exit(stop.exit_status)
    signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
    # Killed, or ended without Python's exit (a signal, os._exit): a crash.
    ending = "timeout" if heard_end == "timeout" else "crash"
    return Supervision(ending=ending, stdin=data, stall=stall)


def _time_the_child(child: int, heard: int, stack: int) -> str | None:
    """Read the child's deadlines until it ends: "timeout" if it was killed past
    one (after it was asked for its stack, written into ``stack``), "done" if it
    said it exits (Supervision.exiting), else None."""
    deadline: float | None = None
    seconds = 0.0
    done = False
    while True:
        left = None if deadline is None else max(0.0, deadline - time.monotonic())
        resumed = continued()
        if not select.select([heard], [], [], left)[0]:
            if continued() != resumed and deadline is not None:
                # Stopped (Ctrl-Z) and continued (fg): the child stood still too.
                deadline = time.monotonic() + seconds
                continue
            _kill(child, STALL_SIGNAL)
            _wait_for_stack(stack)
            if _ended_its_lint(child, heard):
                # Its lint returned while its stack was taken: it may have written
                # its output, which a second run with "timed out" would follow.
                deadline = None
                continue
            _kill(child)
            return "timeout"
        said = os.read(heard, 256).split()
        if not said:
            return "done" if done else None
        if DONE in said:
            done = True
            said = said[: said.index(DONE)]
        if said:
            seconds = float(said[-1])  # the latest (a lone file says twice, at most)
            deadline = time.monotonic() + seconds if seconds else None


def _ended_its_lint(child: int, heard: int) -> bool:
    """Whether the child, stopped first (so that it cannot end its lint between
    the look and the kill), has said anything since its deadline passed: what
    it says next to a deadline is that its lint ended. Continued when it has."""
    _kill(child, signal.SIGSTOP)
    try:  # noqa: SIM105 - contextlib is one more import before the fork
        # Until it is stopped (or has ended); WNOWAIT: its status stays for waitpid.
        os.waitid(os.P_PID, child, os.WSTOPPED | os.WEXITED | os.WNOWAIT)
    except ChildProcessError:
        pass  # nothing to wait for
    if select.select([heard], [], [], 0)[0]:
        _kill(child, signal.SIGCONT)
        return True
    return False


def _wait_for_stack(stack: int) -> None:
    """Until the child's stack begins to arrive, at most STACK_WAIT seconds (it
    writes it at once, from its signal handler), and a moment for the rest."""
    if select.select([stack], [], [], STACK_WAIT)[0]:
        time.sleep(0.05)


def _read_stack(stack: int) -> str:
    """What the child wrote into ``stack`` (it is dead: nothing more comes)."""
    os.set_blocking(stack, False)
    chunks = []
    try:
        while chunk := os.read(stack, 1 << 16):
            chunks.append(chunk)
    except OSError:
        pass  # nothing (more) to read
    return b"".join(chunks).decode(errors="replace")


def _kill(pid: int, signum: int = signal.SIGKILL) -> None:
    try:  # noqa: SIM105 - contextlib is one more import before the fork
        os.kill(pid, signum)
    except ProcessLookupError:
        pass  # it has just ended
