"""How files are linted: one :class:`Executor`, chosen once by :func:`choose_executor`
(docs/design.md, "Processes"); a file's crash or time-out is its result, in input order."""

from __future__ import annotations

import os
import signal
import stat
import time
from collections import deque
from collections.abc import Callable, Sequence
from contextlib import suppress
from dataclasses import field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from .. import debug
from ..model import FileResult
from ..records import record
from .collector import collect_less_often
from .interrupts import STALL_SIGNAL, check_stopped, continued
from .progress import progress_bar, want_progress
from .supervisor import Supervision

if TYPE_CHECKING:
    from multiprocessing.connection import Connection
    from multiprocessing.process import BaseProcess

#: Items a worker holds at once: the one it lints and the next, waiting in its pipe,
#: so that it never idles for the parent's round trip between files (about 0.8 ms a
#: file on a CI gate; benchmarks/run.py --only gate). Only while more items wait than
#: there are other workers (Pool._feed): the last ones go to whichever worker is free.
IN_FLIGHT = 2
#: A worker's memory grows about 2 MiB per 1,000 files it lints (usd-core's bindings
#: keep a small wrapper for every layer a stage handed out): a fresh worker replaces
#: one after this many. A replacement costs about 50 ms (a start and a first lint), 0.5%
#: of 2,000 gate shots' lint, where every 500 it cost 2% of theirs.
WORKER_RECYCLE_AFTER = 2000
MIN_WORKER_MEMORY = 2 << 30  # however many workers share the machine
_READY, _FAILED = -1, -2  # what a worker sends for an index once ready, or failing to start
_WRITING = -3  # what a worker sends before it writes a user's file (hold_deadline)
_REFUSED = -4  # what a worker sends whose USD cannot lint at all: the run's error, as it says
#: Seconds a stopped run (Ctrl-C, SIGTERM) waits for a worker writing a user's file.
WRITE_GRACE = 30.0
_NEVER = float("inf")


class FileLinter(Protocol):
    """A Linter, VariantExplorer, InspectingLinter... (``full_composition``: the retry)."""

    def lint_path(self, path: str, *, full_composition: bool = False) -> FileResult: ...


LinterFactory = Callable[[], FileLinter]


class ExecutionError(Exception):
    """The worker pool could not do its job (not a problem of one file)."""


class Executor(Protocol):
    def run(self, files: Sequence[Any], advance: Callable[[], None]) -> tuple[Any, ...]: ...


def default_jobs() -> int:
    return os.cpu_count() or 1


def lint_paths(
    files: Sequence[str],
    *,
    linter: FileLinter | None = None,
    linter_factory: LinterFactory | None = None,
    jobs: int = 1,
    timeout: float | None = None,
    progress: bool | None = None,
    supervision: Supervision | None = None,
) -> tuple[FileResult, ...]:
    """One result per file, in input order: with ``linter`` (else one the picklable
    ``linter_factory`` builds, as workers do), each within ``timeout`` s (0: none)."""
    count = len(files)
    executor = choose_executor(count, jobs, timeout or None, supervision, linter, linter_factory)
    with progress_bar(count, want_progress(count, progress)) as advance:
        return executor.run(files, advance)


def choose_executor(
    count: int,
    jobs: int,
    timeout: float | None,
    supervision: Supervision | None,
    linter: FileLinter | None,
    linter_factory: LinterFactory | None,
) -> Executor:
    """The one place that decides how ``count`` files are linted."""
    child = supervision if supervision is not None and supervision.ending is None else None
    ending = supervision.ending if supervision is not None else None
    if ending is not None and count == 1:
        pool = Pool(_factory(linter_factory), 1, timeout)
        return AfterSupervisedChild(ending, pool, supervision.stall if supervision else None)
    # After the child's crash, never in this process: what crashed it would end the run.
    if (jobs == 1 and timeout is None and ending is None) or (child is not None and count == 1):
        return InProcess(linter or _factory(linter_factory)(), child, timeout)
    return Pool(_factory(linter_factory), min(jobs, count), timeout)


@record(frozen=True)
class InProcess:
    """Every file in this process. In the supervised child (``supervision``), under
    a worker's memory cap, its supervisor handles a crash and times a lone file."""

    linter: FileLinter
    supervision: Supervision | None = None
    timeout: float | None = None

    def run(self, files: Sequence[str], advance: Callable[[], None]) -> tuple[FileResult, ...]:
        if self.supervision is not None:
            cap_memory(workers=1)
        results = []
        for position, path in enumerate(files):
            if position + 1 < len(files):
                will_read(files[position + 1])
            if self.supervision is not None and self.timeout:
                results.append(self.supervision.timed(self.timeout, lint_one, self.linter, path))
            else:
                results.append(lint_one(self.linter, path))
            check_stopped()
            advance()
        return tuple(results)


@record(frozen=True)
class AfterSupervisedChild:
    """The supervisor's run after its child's "timeout" on the lone file (its result)
    or "crash" (``pool`` lints it again fully composed, as any file a worker died on)."""

    ending: str
    pool: Pool
    #: The child's stack as it timed out (Supervision.stall).
    stall: str | None = None

    def run(self, files: Sequence[str], advance: Callable[[], None]) -> tuple[FileResult, ...]:
        if self.ending == "timeout":
            why = timed_out(self.pool.timeout, self.stall)
            return tuple(file_error(path, why) for path in files)
        return self.pool.run([FullyComposed(path) for path in files], advance)


@record(frozen=True)
class FullyComposed:
    """A file to lint again with the whole stage composed (no fast path)."""

    path: str


def file_error(path: str, why: str) -> FileResult:
    return FileResult(path, status="error", error=f"{path}: {why}")


def lint_one(linter: FileLinter, item: str | FullyComposed) -> FileResult:
    """``linter.lint_path``; an engine failure is the file's error, not the run's."""
    path = _path_of(item)
    try:
        return linter.lint_path(path, full_composition=isinstance(item, FullyComposed))
    except Exception as exc:  # noqa: BLE001 - one broken file never stops the run
        from ..engine import SchemasMissing  # loaded: the linter raised

        # Without the schemas, no file can be linted: the run's error (lint_as_asked).
        if isinstance(exc, SchemasMissing) or getattr(linter, "raise_errors", False):
            raise
        debug.show(exc, f"{path}: internal error")
        return file_error(path, internal_error(exc))


@record
class Pool:
    """``size`` processes (a hung USD call cannot be stopped from inside), each with
    its ``factory()``, answering one item at a time with ``handle(built, item)`` (all
    picklable), the next already sent (IN_FLIGHT). A worker past ``timeout`` or dead
    is replaced, its item's result ``failed(item, why)`` and the item it had not
    started sent again; but a file it died on is first linted again fully composed
    (what composing survives, the fast path's walks of the layers may not)."""

    factory: Callable[[], Any]
    size: int
    timeout: float | None
    handle: Callable[[Any, Any], Any] = lint_one
    failed: Callable[[Any, str], Any] = file_error

    def run(self, items: Sequence[Any], advance: Callable[[], None] = lambda: None) -> tuple:
        import shutil
        import tempfile

        self._results, self._remaining, self._advance = [None] * len(items), len(items), advance
        self._pending = list(reversed(list(enumerate(items))))  # pop() keeps input order
        self._continued = continued()
        self._log_dir = tempfile.mkdtemp(prefix="usdrender-lint-")
        self._workers: list[_Worker] = []
        try:
            while len(self._workers) < min(self.size, len(items)):
                self._workers.append(self._start())
            while self._remaining:
                for worker in self._workers:
                    self._feed(worker)
                self._step()
        finally:
            # A worker writing a user's file finishes it first (hold_deadline).
            for worker in self._workers:
                if worker.writing:
                    with suppress(OSError):
                        worker.conn.poll(WRITE_GRACE)
            # Every worker is killed before any is joined: they exit side by side.
            for worker in self._workers:
                worker.kill()
            for worker in self._workers:
                worker.stop()
            shutil.rmtree(self._log_dir, ignore_errors=True)
        return tuple(self._results)

    def _feed(self, worker: _Worker) -> None:
        """Send a started worker items until it holds IN_FLIGHT (none past its
        recycling). A worker is sent a next item only while more wait than there are
        other workers: a worker still starting or about to finish takes it otherwise
        (two files on two workers held by one ran 1.36x slower than on one worker)."""
        while (
            not worker.starting
            and self._pending
            and len(worker.queue) < IN_FLIGHT
            and worker.linted + len(worker.queue) < WORKER_RECYCLE_AFTER
            and (not worker.queue or len(self._pending) >= len(self._workers))
        ):
            index, item = self._pending.pop()
            try:
                worker.conn.send((index, item))
            except OSError:
                # It died since the last look (a crash on the item before): the
                # item never reached it. _step finds the death by its sentinel.
                self._pending.append((index, item))
                return
            if not worker.queue:  # it starts this one now
                worker.deadline = self._deadline()
            worker.queue.append((index, item))
            if self.handle is lint_one:
                will_read(_path_of(item))

    def _deadline(self) -> float:
        """When an item a worker starts now is timed out."""
        return time.monotonic() + (self.timeout or _NEVER)

    def _start(self) -> _Worker:
        context = _context()  # chosen per worker: a progress bar's thread makes forking unsafe
        parent_end, child_end = context.Pipe()
        # A copy of the settings only: this one holds the run's processes and pipes.
        args = (child_end, replace(self), self._log_dir)
        process = context.Process(target=_worker_main, args=args, daemon=True)
        process.start()
        child_end.close()
        return _Worker(process, parent_end, self._log_dir)

    def _step(self) -> None:
        from multiprocessing.connection import wait

        check_stopped()
        nearest = min(worker.deadline for worker in self._workers)
        left = None if nearest == _NEVER else max(0.0, nearest - time.monotonic())
        handles = [w.conn for w in self._workers] + [w.process.sentinel for w in self._workers]
        ready = wait(handles, left)
        if continued() != self._continued:
            # Stopped (Ctrl-Z) and continued (fg): the workers stood still too, so the
            # files they hold get their whole time again rather than time out.
            self._continued = continued()
            for worker in self._workers:
                if worker.deadline != _NEVER:
                    worker.deadline = self._deadline()
        for worker in list(self._workers):
            if worker.conn in ready:
                try:
                    index, result = worker.conn.recv()
                except (EOFError, OSError):
                    self._lose(worker)
                else:
                    self._receive(worker, index, result)
            elif worker.process.sentinel in ready:
                self._lose(worker)
            elif time.monotonic() >= worker.deadline:
                self._lose(worker, timed_out(self.timeout, worker.stack()))

    def _receive(self, worker: _Worker, index: int, result: Any) -> None:
        if index == _FAILED:
            raise ExecutionError(f"a worker process could not build the linter: {result}")
        if index == _REFUSED:
            raise ExecutionError(result)
        if index == _WRITING:  # until it answers: see hold_deadline
            worker.deadline = _NEVER
            worker.writing = True
            return
        if index == _READY:  # with its USD plugin registration problems
            from ..engine import reported_by_worker

            reported_by_worker(result)
            worker.starting = False
            return
        worker.queue.popleft()  # answered in the order sent
        worker.writing = False
        self._done(index, result)
        worker.linted += 1
        # The next item already waits in its pipe: the worker started it as it answered.
        worker.deadline = self._deadline() if worker.queue else _NEVER
        if worker.linted >= WORKER_RECYCLE_AFTER and self._pending:
            self._replace(worker)

    def _lose(self, worker: _Worker, why: str | None = None) -> None:
        """``worker`` timed out (``why``), or died (None)."""
        crashed = why is None
        died = worker.death() if crashed else ""
        if worker.starting:  # it crashed: a starting worker has no deadline to miss
            # Not CRASHED's "while reading it": it read no file.
            from .address_space import limit_hint

            raise ExecutionError(f"a worker process died while starting {died}{limit_hint()}")
        why = why or f"{CRASHED} {died}"
        if worker.queue:
            index, item = worker.queue.popleft()  # the one it was linting
            self._pending.extend(reversed(worker.queue))  # never started: in input order
            if crashed and self.handle is lint_one and isinstance(item, str):
                self._pending.append((index, FullyComposed(item)))
            else:
                self._done(index, self.failed(_path_of(item), why))
        self._replace(worker)

    def _replace(self, worker: _Worker) -> None:
        worker.stop()
        self._workers.remove(worker)
        if self._pending:
            self._workers.append(self._start())

    def _done(self, index: int, result: Any) -> None:
        self._results[index] = result
        self._remaining -= 1
        self._advance()


@record
class _Worker:
    process: BaseProcess
    conn: Connection
    log_dir: str
    #: Until it says it is ready, it is sent nothing.
    starting: bool = True
    #: The ``(index, item)`` sent and not answered, oldest (the one it lints) first,
    #: and that one's deadline.
    queue: deque[tuple[int, Any]] = field(default_factory=deque)
    deadline: float = _NEVER
    linted: int = 0
    #: Writing a user's file (hold_deadline), until it answers.
    writing: bool = False

    def death(self) -> str:
        """How it died, in parentheses: "(signal SIGABRT: USD fatal error: ...)"."""
        self.process.join(5)
        code = self.process.exitcode
        how = f"exit code {code}"
        if code is not None and code < 0:
            try:
                how = f"signal {signal.Signals(-code).name}"
            except ValueError:
                how = f"signal {-code}"
        said = ""
        with suppress(OSError, UnicodeDecodeError):
            said = _last_words(Path(self.log_dir, f"worker-{self.process.pid}.log").read_text())
        return f"({how}{': ' + said if said else ''})"

    def stack(self) -> str:
        """Its Python stack, which it writes into its log when asked (stalls.listen)."""
        log = Path(self.log_dir, f"worker-{self.process.pid}.log")

        def read() -> str:
            try:
                return log.read_text(errors="replace")
            except OSError:
                return ""

        if self.process.pid is None:
            return ""
        from . import stalls

        with suppress(OSError):
            os.kill(self.process.pid, STALL_SIGNAL)
        return stalls.collect(read)

    def kill(self) -> None:
        self.process.kill()  # idle or not: a worker holds nothing to clean up (dead: a no-op)

    def stop(self) -> None:
        self.kill()
        self.process.join(5)
        self.conn.close()


def _worker_main(conn: Connection, pool: Pool, log_dir: str) -> None:
    """Build the linter, say so, then answer each ``(index, item)``. Its stderr is a log,
    emptied before each item: what USD prints as it aborts makes the one-line error."""
    # Ctrl-C is the parent's to handle (it reaches the process group); SIGTERM ends it.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    die_with_parent(os.getppid())
    cap_memory(pool.size)
    share_cores(pool.size)
    debug.keep_stderr()
    # Nothing of a worker's belongs on stdout, nor may it hold the user's pipe open.
    for fd, path in ((0, os.devnull), (1, os.devnull), (2, f"{log_dir}/worker-{os.getpid()}.log")):
        try:
            opened = os.open(path, os.O_RDWR | os.O_CREAT | os.O_TRUNC | os.O_APPEND)
        except OSError:
            # The run ended while this worker started (Ctrl-C) and removed its
            # log folder: nothing is wanted of it, and its stderr is the user's.
            return
        os.dup2(opened, fd)
        os.close(opened)
    from . import stalls

    stalls.listen(2)  # a time-out asks where it was (_Worker.stack)
    collect_less_often()  # a fork server's worker does not inherit the command's
    try:
        from pxr import Usd

        from ..engine import register_plugins

        problems = register_plugins()  # before any other USD call: engine/plugins.py
        linter = pool.factory()
        Usd.Stage.CreateInMemory()  # USD's plugins load now, not in the first file's time
    except BaseException as exc:  # noqa: BLE001 - reported to the parent, not printed
        debug.show(exc, "a worker could not start")
        from ..engine import SchemasMissing

        if isinstance(exc, SchemasMissing):
            from .address_space import schemas_missing

            conn.send((_REFUSED, schemas_missing(exc)))
        else:
            conn.send((_FAILED, f"{type(exc).__name__}: {exc}"))
        return
    conn.send((_READY, problems))
    global _parent
    _parent = conn
    with suppress(EOFError, OSError):  # the parent is gone
        while True:
            index, item = conn.recv()
            os.ftruncate(2, 0)  # appending: the next line is the first
            try:  # the result holds only plain values; the stage dies with the handler
                result = pool.handle(linter, item)
            except Exception as exc:  # noqa: BLE001 - a handler's bug costs only its item
                debug.show(exc, "internal error")
                result = pool.failed(_path_of(item), internal_error(exc))
            conn.send((index, result))
            signal.signal(signal.SIGTERM, signal.SIG_DFL)  # after hold_deadline


#: In a worker process: its end of the pipe to the parent (hold_deadline).
_parent: Connection | None = None


def hold_deadline() -> None:
    """In a worker: the item it handles is neither timed out nor stopped from now
    on (SIGTERM is ignored until it is answered: the parent, stopped, waits
    WRITE_GRACE for it). Said before writing a user's file: a kill in the middle
    would leave the temporary file and the backup hard link of the write beside it
    (layers.writing). Ignored, not blocked: USD's threads would take a blocked one."""
    if _parent is not None:
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        _parent.send((_WRITING, None))


def _context() -> Any:
    import multiprocessing

    # One thread (USD starts its pool at its first stage) forks safely, and the
    # workers start with USD imported (issue 6); else a forkserver that imported it.
    with suppress(OSError):  # not Linux: its threads are not known
        if len(os.listdir("/proc/self/task")) == 1:
            return multiprocessing.get_context("fork")
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(["usdrender_lint.engine"])
    _start_forkserver()
    return context


def _start_forkserver() -> None:
    """Start the fork server with SIGINT ignored, as a signal's disposition
    passes through exec: it keeps ignoring it, and so do the workers it forks
    (they restore its handlers). Else a Ctrl-C while it imports the engine,
    or while a worker unpickles its arguments before ``_worker_main`` ignores
    SIGINT, printed a KeyboardInterrupt traceback. SIGINT is blocked here
    meanwhile, so a Ctrl-C in that instant still reaches the parent."""
    import threading
    from multiprocessing import forkserver

    if threading.current_thread() is not threading.main_thread():
        forkserver.ensure_running()  # only the main thread may set a handler
        return
    blocked = hasattr(signal, "pthread_sigmask")
    if blocked:
        previous_mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        forkserver.ensure_running()
    finally:
        signal.signal(signal.SIGINT, previous)
        if blocked:
            signal.pthread_sigmask(signal.SIG_SETMASK, previous_mask)


def die_with_parent(parent: int) -> None:
    """Have Linux kill this process when its ``parent`` dies, even of SIGKILL."""
    import ctypes

    with suppress(OSError, AttributeError):  # AttributeError: no prctl, not Linux
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # 1: PR_SET_PDEATHSIG
    if os.getppid() != parent:  # it died before the call took effect
        os.kill(os.getpid(), signal.SIGKILL)


def worker_memory_limit(workers: int) -> int:
    """Bytes one of ``workers`` may allocate, together 90% of the host's (or cgroup's):
    a corrupt crate can make USD allocate without end; capped, it fails at once."""
    total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    for path in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        with suppress(OSError):
            text = Path(path).read_text().strip()
            if text.isdigit() and int(text) < 1 << 60:  # "max" or a huge number: no limit
                total = min(total, int(text))
    return max(MIN_WORKER_MEMORY, int(total * 0.9) // max(workers, 1))


def share_cores(workers: int) -> None:
    """Give a worker of ``workers`` its share of the cores for USD's threads, at
    least one. USD opens a stage on every core; with a worker per core, a worker's
    second thread only competes with the other workers (on 2 cores, ``--jobs 2``
    over 200 CI-gate shots took 2.82 s against 2.97 s, over 1,000 10.6 s against
    11.1 s, user time 4% less). A limit the user set (``PXR_WORK_THREAD_LIMIT``)
    stands."""
    if workers < 2 or "PXR_WORK_THREAD_LIMIT" in os.environ:
        return
    from pxr import Work

    share = max(1, Work.GetPhysicalConcurrencyLimit() // workers)
    if share < Work.GetConcurrencyLimit():
        Work.SetConcurrencyLimit(share)


def cap_memory(workers: int) -> None:
    """In a worker or the supervised child: at most its share (worker_memory_limit)."""
    import resource

    soft, hard = resource.getrlimit(resource.RLIMIT_DATA)
    limit = worker_memory_limit(workers)  # set only below the soft limit: below the hard one
    if soft == resource.RLIM_INFINITY or limit < soft:
        with suppress(ValueError, OSError):
            resource.setrlimit(resource.RLIMIT_DATA, (limit, hard))


def _factory(linter_factory: LinterFactory | None) -> LinterFactory:
    if linter_factory is None:
        raise ValueError("worker processes need a picklable linter_factory")
    return linter_factory


#: The most of a file :func:`will_read` asks the kernel to read ahead (a crate's
#: reader reads only the parts it needs; a text layer is read whole).
WILL_READ_BYTES = 16 << 20


def will_read(path: str) -> None:
    """Have the kernel read the regular file at ``path`` into its cache now,
    without waiting: a file sent to a worker (or next in this process) is read
    from disk while the one before it is linted (``posix_fadvise`` WILLNEED: no
    thread, none of our CPU; CI runners lint freshly checked-out, uncached files).
    Opened without blocking (a FIFO never stops the run); any error is ignored,
    as the lint then reports what it cannot read."""
    advise = getattr(os, "posix_fadvise", None)  # not on macOS or Windows
    if advise is None:
        return
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except (OSError, ValueError, TypeError):
        return
    try:
        info = os.fstat(fd)
        if stat.S_ISREG(info.st_mode):
            advise(fd, 0, min(info.st_size, WILL_READ_BYTES), os.POSIX_FADV_WILLNEED)
    except OSError:
        pass
    finally:
        os.close(fd)


def _path_of(item: Any) -> Any:
    return item.path if isinstance(item, FullyComposed) else item


#: Why a file has no result when the process linting it died.
CRASHED = "the linter process crashed while reading it"


def timed_out(timeout: float | None, dump: str | None = None) -> str:
    """A time-out's message; ``dump``: the lint's stack as it timed out (stalls.py),
    whose rule or step the message names."""
    from . import stalls  # a time-out's only

    where = stalls.site(dump) if dump else None
    at = f" {where}" if where else ""
    return f"timed out after {timeout:g} s{at} (raise --timeout, or 0 for no limit)"


def internal_error(exc: Exception) -> str:
    # USD's errors span lines; the report gives each file one line.
    return f"internal error: {type(exc).__name__}: {' '.join(str(exc).split())}"


def _last_words(printed: str) -> str:
    """USD's "FATAL ERROR: ..." line, else the last (at most 200 characters)."""
    lines = [line.strip() for line in printed.splitlines() if line.strip()]
    fatal = [line[line.index("FATAL ERROR:") :] for line in lines if "FATAL ERROR:" in line]
    if fatal:
        return ("USD " + fatal[-1].replace("FATAL ERROR", "fatal error", 1))[:200]
    return lines[-1][:200] if lines else ""
