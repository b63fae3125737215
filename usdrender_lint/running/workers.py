"""How files are linted: one :class:`Executor`, chosen once from the run's jobs,
time-out and supervision by :func:`choose_executor` (docs/design.md, "Processes").

- :class:`InProcess`: every file in this process (``--jobs 1 --timeout 0``, the
  Python API, and the supervised child's lone file, which its supervisor times).
- :class:`Pool`: worker processes, each file under the time-out. A hung or
  crashing USD call cannot be interrupted from inside the process that makes it.
- :class:`AfterSupervisedChild`: the supervisor's own run when its child did
  not finish the lone file.

A crash or a time-out of a file is the result an executor returns for it, in
input order. ``multiprocessing`` is imported only when a pool runs.
"""

from __future__ import annotations

import os
import signal
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from .. import debug
from ..model import FileResult
from ..records import record
from .interrupts import check_stopped, default_signals_in_worker
from .supervisor import Supervision

if TYPE_CHECKING:
    from multiprocessing.connection import Connection
    from multiprocessing.process import BaseProcess

#: A progress bar is worth drawing only for runs longer than this many files.
PROGRESS_MIN_FILES = 20
#: How long a new worker may take to import USD and build its linter.
WORKER_START_LIMIT = 120.0
#: Files a worker lints before a fresh one replaces it: usd-core's bindings keep a
#: small wrapper for every layer a stage ever handed out (about 1 MiB per 1,000 files).
WORKER_RECYCLE_AFTER = 500
#: The least memory a worker is allowed, however many there are.
MIN_WORKER_MEMORY = 2 << 30
#: Environment variables that configure the linter, handed to every worker.
ENV_PREFIX = "USDRENDER_LINT_"


class FileLinter(Protocol):
    """An engine Linter, a VariantExplorer, running.inspect's InspectingLinter...
    ``full_composition`` composes the whole stage (the retry after a crash)."""

    def lint_path(self, path: str, *, full_composition: bool = False) -> FileResult: ...


LinterFactory = Callable[[], FileLinter]
#: What a worker does with each item: (what the factory built, the item) -> a picklable result.
Handler = Callable[[Any, Any], Any]
#: The result for an item whose worker timed out or died: (item, why) -> result.
OnFailure = Callable[[Any, str], Any]


class ExecutionError(Exception):
    """The worker pool could not do its job (not a problem of one file)."""


class Executor(Protocol):
    """Lints files, one result per file in input order."""

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
    """One result per file, in input order. ``linter`` lints in this process (else one
    built by ``linter_factory``, which workers call: it must be picklable); ``timeout``
    (seconds, None or 0: none) bounds each file; ``progress`` None draws a bar on a
    terminal when there are many files."""
    if jobs < 1:
        raise ValueError(f"jobs must be at least 1, got {jobs}")
    executor = choose_executor(
        len(files),
        jobs=jobs,
        timeout=timeout or None,
        supervision=supervision,
        linter=linter,
        linter_factory=linter_factory,
    )
    show = _want_progress(len(files)) if progress is None else progress
    with _progress_bar(len(files), show) as advance:
        return executor.run(files, advance)


def choose_executor(
    count: int,
    *,
    jobs: int,
    timeout: float | None,
    supervision: Supervision | None,
    linter: FileLinter | None,
    linter_factory: LinterFactory | None,
) -> Executor:
    """The one place that decides how ``count`` files are linted."""
    child = supervision if supervision is not None and supervision.child else None
    if supervision is not None and supervision.ending is not None and count == 1:
        return AfterSupervisedChild(supervision.ending, Pool(_factory(linter_factory), 1, timeout))
    if (jobs == 1 and timeout is None) or (child is not None and count == 1):
        return InProcess(linter or _factory(linter_factory)(), child, timeout)
    return Pool(_factory(linter_factory), min(jobs, count), timeout)


@record(frozen=True)
class InProcess:
    """Every file in this process, one after another. In the supervised child
    (``supervision``) under the pool's memory cap, a crash left to the supervisor,
    which also keeps the lone file's ``timeout``."""

    linter: FileLinter
    supervision: Supervision | None = None
    timeout: float | None = None

    def run(self, files: Sequence[str], advance: Callable[[], None]) -> tuple[FileResult, ...]:
        if self.supervision is not None:
            _limit_memory(worker_memory_limit(1))
        timer = self.supervision if self.timeout else None
        results = []
        for path in files:
            if timer is not None:
                timer.lint_started(self.timeout)
            try:
                results.append(lint_one(self.linter, path))
            finally:
                if timer is not None:
                    timer.lint_ended()
            check_stopped()
            advance()
        return tuple(results)


@record(frozen=True)
class AfterSupervisedChild:
    """The supervisor's own run when its child did not finish the lone file
    (``ending``): a "timeout" is the file's result; after a "crash" ``pool`` lints
    it once more fully composed, as it does any file a worker died on."""

    ending: str
    pool: Pool

    def run(self, files: Sequence[str], advance: Callable[[], None]) -> tuple[FileResult, ...]:
        if self.ending == "timeout":
            return tuple(file_error(path, _timed_out(self.pool.timeout)) for path in files)
        return self.pool.run([FullyComposed(path) for path in files], advance)


@record(frozen=True)
class FullyComposed:
    """A file to lint again with the whole stage composed (no fast path)."""

    path: str


def file_error(path: str, why: str) -> FileResult:
    """The result for a file that could not be linted: ``FILE: why``."""
    return FileResult(path, status="error", error=f"{path}: {why}")


def lint_one(linter: FileLinter, path: str | FullyComposed) -> FileResult:
    """``linter.lint_path``, an unexpected engine failure turned into this file's
    error result so that the other files are still linted."""
    full = isinstance(path, FullyComposed)
    name = _path_of(path)
    try:
        # Only the retry passes the keyword: any linter with lint_path(path) works.
        return linter.lint_path(name, full_composition=True) if full else linter.lint_path(name)
    except Exception as exc:  # noqa: BLE001 - one broken file never stops the run
        if getattr(linter, "raise_errors", False):
            raise
        debug.show(exc, f"{name}: internal error")
        return file_error(name, _internal_error(exc))


class Pool:
    """``size`` worker processes, each building its linter once (``factory``,
    picklable) and answering one item at a time with ``handle``. A worker past
    ``timeout`` or dead is replaced and its item's result is ``failed(item,
    why)``; a file a worker died on is first linted once more fully composed
    (what composing survives, the fast path's walks of the layers may not)."""

    def __init__(
        self,
        factory: Callable[[], Any],
        size: int,
        timeout: float | None,
        handle: Handler = lint_one,
        failed: OnFailure = file_error,
    ) -> None:
        self.factory, self.size, self.timeout = factory, size, timeout or None
        self.handle, self.failed = handle, failed
        self._workers: list[_Worker] = []
        self._pending: list[tuple[int, Any]] = []
        self._results: list[Any] = []
        self._started = 0
        self._log_dir = ""

    def run(self, items: Sequence[Any], advance: Callable[[], None]) -> tuple[Any, ...]:
        import shutil
        import tempfile

        self._results, self._advance = [_PENDING] * len(items), advance
        self._pending = list(reversed(list(enumerate(items))))  # pop() keeps input order
        self._log_dir = tempfile.mkdtemp(prefix="usdrender-lint-")
        try:
            while len(self._workers) < min(self.size, len(items)):
                self._workers.append(self._start())
            while _PENDING in self._results:
                for worker in self._workers:
                    if worker.ready and worker.task is None and self._pending:
                        index, item = self._pending.pop()
                        worker.task = (index, item, time.monotonic() + (self.timeout or _NEVER))
                        worker.conn.send((index, item))
                self._step()
        finally:
            for worker in self._workers:
                worker.stop()
            shutil.rmtree(self._log_dir, ignore_errors=True)
        return tuple(self._results)

    def _start(self) -> _Worker:
        context = _context()  # chosen per worker: a progress bar's thread makes forking unsafe
        parent_end, child_end = context.Pipe()
        self._started += 1
        log_path = os.path.join(self._log_dir, f"worker-{self._started}.log")
        settings_env = {k: v for k, v in os.environ.items() if k.startswith(ENV_PREFIX)}
        process = context.Process(
            target=_worker_main,
            args=(child_end, self.factory, self.handle, self.failed, log_path, settings_env)
            + (worker_memory_limit(self.size), worker_usd_threads(self.size)),
            daemon=True,
        )
        process.start()
        child_end.close()
        return _Worker(process, parent_end, log_path, time.monotonic() + WORKER_START_LIMIT)

    def _step(self) -> None:
        """Wait for one message, death or deadline, and handle it."""
        from multiprocessing.connection import wait

        check_stopped()
        nearest = min(worker.deadline for worker in self._workers)
        left = None if nearest == _NEVER else max(0.0, nearest - time.monotonic())
        handles = [w.conn for w in self._workers] + [w.process.sentinel for w in self._workers]
        ready = set(wait(handles, left))
        for worker in list(self._workers):
            if worker.conn in ready:
                self._hear(worker)
            elif worker.process.sentinel in ready:
                self._lose(worker, worker.death(), crashed=True)
            elif time.monotonic() >= worker.deadline:
                if not worker.ready:
                    raise ExecutionError(
                        f"a worker process did not start within {WORKER_START_LIMIT:g} s"
                    )
                self._lose(worker, _timed_out(self.timeout))

    def _hear(self, worker: _Worker) -> None:
        try:
            kind, payload = worker.conn.recv()
        except (EOFError, OSError):
            self._lose(worker, worker.death(), crashed=True)
            return
        if kind == "failed":
            raise ExecutionError(f"a worker process could not build the linter: {payload}")
        if kind == "ready":
            worker.ready = True
        else:
            self._done(kind, payload)
            worker.task, worker.linted = None, worker.linted + 1
            if worker.linted >= WORKER_RECYCLE_AFTER and self._pending:
                self._replace(worker)

    def _lose(self, worker: _Worker, why: str, crashed: bool = False) -> None:
        """Replace a worker that died or ran out of time, with its item's result
        (or, when it died on a file the fast path read, that file queued again)."""
        if not worker.ready:
            raise ExecutionError(f"a worker process died while starting: {why}")
        if worker.task is not None:
            index, item, _ = worker.task
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
        self._advance()


_NEVER = float("inf")
#: A result not yet in (None is a result: run_bounded's handlers may answer it).
_PENDING: Any = object()


@record
class _Worker:
    process: BaseProcess
    conn: Connection
    #: Where the worker's stderr goes.
    log_path: str
    #: When it must have started.
    start_by: float
    ready: bool = False
    #: (index, item, deadline) of the item being handled, if any.
    task: tuple[int, Any, float] | None = None
    linted: int = 0

    @property
    def deadline(self) -> float:
        if self.task is not None:
            return self.task[2]
        return _NEVER if self.ready else self.start_by

    def death(self) -> str:
        """Why it died, in one line."""
        self.process.join(5)
        try:
            printed = Path(self.log_path).read_text(encoding="utf-8", errors="replace")
        except OSError:
            printed = ""
        return _crash(self.process.exitcode, printed)

    def stop(self) -> None:
        """Ask an idle worker to end; kill a busy one, or one that does not end."""
        with suppress(OSError, ValueError):
            if self.process.is_alive() and self.task is None:
                self.conn.send(None)
                self.process.join(2)
        if self.process.is_alive():
            self.process.kill()
        self.process.join(5)
        self.conn.close()


def run_bounded(
    items: Sequence[Any],
    *,
    factory: Callable[[], Any],
    handle: Handler,
    failed: OnFailure,
    jobs: int = 1,
    timeout: float | None = None,
) -> list[Any]:
    """``handle(factory(), item)`` for each item (in input order), in a pool of
    worker processes (see :class:`Pool`); ``factory``, ``handle`` and ``failed``
    must be picklable (module-level)."""
    return list(Pool(factory, jobs, timeout, handle, failed).run(items, lambda: None))


def _worker_main(
    conn: Connection,
    factory: Callable[[], Any],
    handle: Handler,
    failed: OnFailure,
    log_path: str,
    settings_env: dict[str, str],
    memory_limit: int | None,
    usd_threads: int | None,
) -> None:
    """Build the linter, say ready, then answer each ``(index, item)`` until ``None``.

    Its stderr goes to ``log_path``, emptied before each item: what USD prints when
    it aborts becomes part of the one-line error. ``settings_env`` is the parent's
    ``USDRENDER_LINT_*`` environment now (a forkserver's may be older)."""
    default_signals_in_worker()
    die_with_parent(os.getppid())
    _limit_memory(memory_limit)
    if usd_threads is not None:
        from pxr import Work

        Work.SetConcurrencyLimit(usd_threads)
    for name in [n for n in os.environ if n.startswith(ENV_PREFIX)]:
        del os.environ[name]
    os.environ.update(settings_env)
    debug.keep_stderr()
    log = os.open(log_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    null = os.open(os.devnull, os.O_RDWR)
    # Nothing of a worker's belongs on stdout, nor may it hold the user's pipe open.
    for fd, target in ((0, null), (1, null), (2, log)):
        os.dup2(target, fd)
    os.close(log)
    os.close(null)
    try:
        from pxr import Usd

        linter = factory()
        Usd.Stage.CreateInMemory()  # USD's plugins load now, not in the first file's time
    except BaseException as exc:  # noqa: BLE001 - reported to the parent, not printed
        debug.show(exc, "a worker could not start")
        conn.send(("failed", f"{type(exc).__name__}: {exc}"))
        return
    conn.send(("ready", None))
    with suppress(EOFError, OSError):
        for index, item in iter(conn.recv, None):
            os.ftruncate(2, 0)
            os.lseek(2, 0, os.SEEK_SET)
            try:  # the result holds only plain values; the stage dies with the handler
                result = handle(linter, item)
            except Exception as exc:  # noqa: BLE001 - a handler's bug costs only its item
                debug.show(exc, "internal error")
                result = failed(_path_of(item), _internal_error(exc))
            conn.send((index, result))


def _context() -> Any:
    import multiprocessing

    methods = multiprocessing.get_all_start_methods()
    # A process still running one thread (USD starts its thread pool with the first
    # stage it opens) forks safely, and its workers start with USD and the rules
    # imported: no interpreter start per run (issue 6).
    if "fork" in methods and _single_threaded():
        return multiprocessing.get_context("fork")
    # Else a server that has imported USD forks them, single-threaded.
    if "forkserver" in methods:
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(["usdrender_lint.engine"])
        return context
    return multiprocessing.get_context("spawn")


def _single_threaded() -> bool:
    """True when this process runs one thread (known on Linux only)."""
    try:
        return len(os.listdir("/proc/self/task")) == 1
    except OSError:
        return False


def die_with_parent(parent: int) -> None:
    """Have Linux kill this process when its parent (pid ``parent``) dies, even
    by SIGKILL (``prctl(PR_SET_PDEATHSIG)``); elsewhere the parent's clean-up
    must do. A parent already gone ends this process now."""
    if not sys.platform.startswith("linux"):
        return
    import ctypes

    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # 1: PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:  # it died before the call took effect
        os.kill(os.getpid(), signal.SIGKILL)


def worker_usd_threads(workers: int) -> int | None:
    """USD threads per worker when several share the machine: each its share of
    the cores (at least one); USD would start a thread per core in every worker
    (500 small shots, --jobs 2 on 2 cores: 1.95 s -> 1.91 s). None (USD's default)
    for one worker, or when the user set ``PXR_WORK_THREAD_LIMIT``."""
    if workers < 2 or os.environ.get("PXR_WORK_THREAD_LIMIT"):
        return None
    return max(1, default_jobs() // workers)


def worker_memory_limit(workers: int) -> int | None:
    """Bytes of data one worker may allocate, so that the workers together stay
    within 90% of the machine's (or container's) memory: a corrupt crate can make
    USD allocate tens of GiB; capped, the allocation fails (``std::bad_alloc``)."""
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return None
    for path in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        with suppress(OSError):
            text = Path(path).read_text().strip()
            if text.isdigit() and int(text) < 1 << 60:  # "max" or a huge number: no limit
                total = min(total, int(text))
                break
    return max(MIN_WORKER_MEMORY, int(total * 0.9) // max(workers, 1))


def _limit_memory(limit: int | None) -> None:
    import resource

    soft, hard = resource.getrlimit(resource.RLIMIT_DATA)
    if limit is not None and hard != resource.RLIM_INFINITY:
        limit = min(limit, hard)
    if limit is not None and (soft == resource.RLIM_INFINITY or limit < soft):
        with suppress(ValueError, OSError):
            resource.setrlimit(resource.RLIMIT_DATA, (limit, hard))


def _path_of(item: Any) -> Any:
    return item.path if isinstance(item, FullyComposed) else item


def _factory(linter_factory: LinterFactory | None) -> LinterFactory:
    if linter_factory is None:
        raise ValueError("worker processes need a picklable linter_factory")
    return linter_factory


def _timed_out(timeout: float | None) -> str:
    return f"timed out after {timeout:g} s (raise --timeout, or 0 for no limit)"


def _internal_error(exc: Exception) -> str:
    # USD's errors span lines; the report gives each file one line.
    return f"internal error: {type(exc).__name__}: {' '.join(str(exc).split())}"


def _crash(code: int | None, printed: str) -> str:
    """Why a worker died, in one line: the signal or exit code, and what it
    ``printed`` on stderr."""
    if code is not None and code < 0:
        try:
            how = f"signal {signal.Signals(-code).name}"
        except ValueError:
            how = f"signal {-code}"
    else:
        how = f"exit code {code}"
    said = _last_words(printed)
    return f"the linter process crashed while reading it ({how}{': ' + said if said else ''})"


def _last_words(printed: str) -> str:
    """USD's "FATAL ERROR: ..." line if it printed one, else its last line (at
    most 200 characters)."""
    lines = [line.strip() for line in printed.splitlines() if line.strip()]
    fatal = [line[line.index("FATAL ERROR:") :] for line in lines if "FATAL ERROR:" in line]
    if fatal:
        return ("USD " + fatal[-1].replace("FATAL ERROR", "fatal error", 1))[:200]
    return lines[-1][:200] if lines else ""


def _want_progress(count: int) -> bool:
    # Never in CI logs: only a real terminal gets the bar.
    return count > PROGRESS_MIN_FILES and sys.stderr.isatty()


@contextmanager
def _progress_bar(total: int, show: bool) -> Iterator[Callable[[], None]]:
    if not show:
        yield lambda: None
        return
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeRemainingColumn

    columns = ("linting", BarColumn(), MofNCompleteColumn(), TimeRemainingColumn())
    with Progress(*columns, console=Console(stderr=True), transient=True) as bar:
        task = bar.add_task("lint", total=total)
        yield lambda: bar.advance(task)
