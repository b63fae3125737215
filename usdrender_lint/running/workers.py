"""How files are executed: one :class:`Executor`, chosen once from the run's
jobs, time-out and supervision (:func:`choose_executor`), lints every file.

- :class:`InProcess`: ``--jobs 1 --timeout 0`` and the Python API; in the
  supervised child (running/supervisor.py), under the pool's memory cap.
- :class:`SupervisedChild`: the lone file of a supervised ``check`` or
  ``spec``, linted in this process while its supervisor times it: past the
  time-out or on a crash the supervisor runs the command again.
- :class:`AfterSupervisedChild`: that second run, with what ended the child
  (its own input): a time-out is the file's error result, a crash the file
  linted again fully composed in a worker.
- :class:`Pool`: worker processes with a per-file time limit. A hung or
  crashing USD call cannot be interrupted from inside the process that makes
  it, so a time limit needs processes that can be killed. Each worker builds
  its own :class:`~usdrender_lint.engine.Linter` once (from a picklable
  factory, e.g. the settings) and lints one file at a time; a worker that runs
  past the limit or dies is replaced, and its file is reported as an error (a
  crash after one more try, fully composed).

A crash or a time-out of a file is a result each executor returns. Results
come back in input order, so the output never depends on ``jobs``.
``multiprocessing`` and the other modules of the pool are imported only when
a pool runs: linting in this process does not pay for them.
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
from . import supervisor
from .interrupts import check_stopped, default_signals_in_worker
from .supervisor import Supervision, die_with_parent

if TYPE_CHECKING:
    import multiprocessing.context
    import multiprocessing.process
    from multiprocessing.connection import Connection

    # The contexts _context chooses from (BaseContext declares no Process).
    _Context = (
        multiprocessing.context.ForkContext
        | multiprocessing.context.ForkServerContext
        | multiprocessing.context.SpawnContext
    )

#: A progress bar is worth drawing only for runs longer than this many files.
PROGRESS_MIN_FILES = 20
#: How long a new worker may take to import USD and build its linter.
WORKER_START_LIMIT = 120.0
#: Files a worker lints before a fresh one replaces it. usd-core's Python
#: bindings keep a small wrapper for every layer a stage ever handed out, even
#: after the layer is gone (about 1 MiB per 1,000 files), so long runs recycle.
WORKER_RECYCLE_AFTER = 500
#: The least memory a worker is allowed, however many there are.
MIN_WORKER_MEMORY = 2 << 30


class FileLinter(Protocol):
    """What the pool needs of a linter: an engine Linter, a VariantExplorer or
    running.inspect's InspectingLinter. ``full_composition`` composes the
    whole stage (a file a worker died on in the fast path is linted again so)."""

    def lint_path(self, path: str, *, full_composition: bool = False) -> FileResult: ...


LinterFactory = Callable[[], FileLinter]
#: What a worker does with each item: (what the factory built, the item) -> a
#: picklable result. It must not raise (lint_one turns failures into results).
Handler = Callable[[Any, Any], Any]
#: The result for an item whose worker timed out or died: (item, why) -> result.
OnFailure = Callable[[Any, str], Any]
#: Environment variables that configure the linter, handed to every worker.
ENV_PREFIX = "USDRENDER_LINT_"


class ExecutionError(Exception):
    """The worker pool could not do its job (not a problem of one file)."""


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
    """Lint ``files`` and return one result per file, in input order, with
    the executor :func:`choose_executor` picks. ``linter`` (or one built by
    ``linter_factory``) lints in this process; worker processes each call the
    picklable ``linter_factory``. ``timeout`` (seconds, None or 0 for none)
    bounds each file. ``progress`` None draws a bar on stderr only when it is
    a terminal and there are many files.
    """
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


class Executor(Protocol):
    """Lints files, one result per file in input order; a crash or a time-out
    of one file is that file's result."""

    def run(self, files: Sequence[str], advance: Callable[[], None]) -> tuple[FileResult, ...]: ...


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
    if supervision is not None and supervision.ending is not None and count == 1:
        return AfterSupervisedChild(supervision.ending, _factory(linter_factory), timeout)
    child = supervision is not None and supervision.child
    if jobs == 1 and timeout is None:
        return InProcess(linter or _build(linter_factory), guarded=child)
    if count == 1 and supervision is not None and child:
        return SupervisedChild(linter or _build(linter_factory), timeout, supervision)
    return Pool(_factory(linter_factory), min(jobs, count), timeout)


@record(frozen=True)
class InProcess:
    """Every file in this process, one after another. ``guarded``: in the
    supervised child, whose supervisor reports a crash (and composes the whole
    stage in its run after it) and whose memory the pool's cap bounds."""

    linter: FileLinter
    guarded: bool = False

    def run(self, files: Sequence[str], advance: Callable[[], None]) -> tuple[FileResult, ...]:
        if self.guarded:
            _guard_supervised()
        results = []
        for path in files:
            results.append(lint_one(self.linter, path))
            check_stopped()
            advance()
        return tuple(results)


@record(frozen=True)
class SupervisedChild:
    """The supervised child's lone file, linted in this process, timed by its
    supervisor: told when the lint starts and ends, it kills the child past
    ``timeout`` and reports that (:class:`AfterSupervisedChild`), as it does
    a crash."""

    linter: FileLinter
    timeout: float | None
    supervision: Supervision

    def run(self, files: Sequence[str], advance: Callable[[], None]) -> tuple[FileResult, ...]:
        (path,) = files
        _guard_supervised()
        supervisor.lint_started(self.supervision, self.timeout)
        try:
            return (lint_one(self.linter, path),)
        finally:
            supervisor.lint_ended(self.supervision)


@record(frozen=True)
class AfterSupervisedChild:
    """The supervisor's run after its child did not finish the lone file:
    ``ending`` "timeout" is the file's time-out; "crash": the file is linted
    again in a worker with the whole stage composed (the pool's retry)."""

    ending: str
    linter_factory: LinterFactory
    timeout: float | None

    def run(self, files: Sequence[str], advance: Callable[[], None]) -> tuple[FileResult, ...]:
        (path,) = files
        if self.ending == "timeout":
            return (file_error(path, _timed_out(self.timeout)),)
        pool = _Pool(self.linter_factory, 1, self.timeout, advance)
        return pool.run([FullyComposed(path)])


@record(frozen=True)
class Pool:
    """``size`` worker processes (see :class:`_Pool`)."""

    linter_factory: LinterFactory
    size: int
    timeout: float | None

    def run(self, files: Sequence[str], advance: Callable[[], None]) -> tuple[FileResult, ...]:
        return _Pool(self.linter_factory, self.size, self.timeout, advance).run(files)


def run_bounded(
    items: Sequence[Any],
    *,
    factory: Callable[[], Any],
    handle: Handler,
    failed: OnFailure,
    jobs: int = 1,
    timeout: float | None = None,
) -> list[Any]:
    """``handle(factory(), item)`` for each item, in worker processes that are
    killed when an item runs past ``timeout`` seconds (None or 0: no limit) or
    die on it; such an item's result is ``failed(item, why)``. In input order.
    ``factory`` and ``handle`` must be picklable (module-level)."""
    if not items:
        return []
    pool = _Pool(factory, min(jobs, len(items)), timeout or None, lambda: None, handle, failed)
    return list(pool.run(items))


def file_error(path: str, why: str) -> FileResult:
    """The result for a file a worker could not lint: ``FILE: why``."""
    return FileResult(path, status="error", error=f"{path}: {why}")


@record(frozen=True)
class FullyComposed:
    """A file to lint again with the whole stage composed (no fast path)."""

    path: str


def _path_of(item: Any) -> Any:
    return item.path if isinstance(item, FullyComposed) else item


def lint_one(linter: FileLinter, path: str | FullyComposed) -> FileResult:
    """``linter.lint_path`` that turns an unexpected engine failure into an
    error result for this file, so the other files are still linted."""
    if isinstance(path, FullyComposed):
        path = path.path
        full = True
    else:
        full = False
    try:
        # Only the retry passes the keyword: any linter with lint_path(path) works.
        return linter.lint_path(path, full_composition=True) if full else linter.lint_path(path)
    except Exception as exc:  # noqa: BLE001 - one broken file never stops the run
        if getattr(linter, "raise_errors", False):
            raise
        debug.show(exc, f"{path}: internal error")
        # USD's errors span lines; the report gives each file one line.
        detail = " ".join(str(exc).split())
        return FileResult(
            path, status="error", error=f"{path}: internal error: {type(exc).__name__}: {detail}"
        )


# -- progress -----------------------------------------------------------------------


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

    with Progress(
        "linting",
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=Console(stderr=True),
        transient=True,
    ) as bar:
        task = bar.add_task("lint", total=total)
        yield lambda: bar.advance(task)


# -- the supervised child ----------------------------------------------------------


def _factory(linter_factory: LinterFactory | None) -> LinterFactory:
    if linter_factory is None:
        raise ValueError("worker processes need a picklable linter_factory")
    return linter_factory


def _build(linter_factory: LinterFactory | None) -> FileLinter:
    return _factory(linter_factory)()


def _guard_supervised() -> None:
    """What the supervised child needs before it lints in its own process: a
    file that makes USD allocate without end fails its allocation (the pool's
    cap)."""
    _limit_memory(worker_memory_limit(1))  # the pool's cap, for one worker


def _timed_out(timeout: float | None) -> str:
    return f"timed out after {timeout:g} s (raise --timeout, or 0 for no limit)"


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


# -- worker processes ---------------------------------------------------------------


def _single_threaded() -> bool:
    """True when this process runs one thread (known on Linux only)."""
    try:
        return len(os.listdir("/proc/self/task")) == 1
    except OSError:
        return False


def _context() -> _Context:
    import multiprocessing

    # A process still running one thread (USD starts its thread pool with the
    # first stage it opens; the command line opens none itself) forks safely,
    # and its workers start with USD and the rules already imported, which
    # saves a whole interpreter start per run (issue 6, start-up).
    if "fork" in multiprocessing.get_all_start_methods() and _single_threaded():
        return multiprocessing.get_context("fork")
    # forkserver forks workers from a clean, single-threaded server that has
    # only imported USD: cheap to replace, and no fork of a process whose USD
    # thread pool is running (which can deadlock the child).
    if "forkserver" in multiprocessing.get_all_start_methods():
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(["usdrender_lint.engine"])
        return context
    return multiprocessing.get_context("spawn")


def _worker_main(
    conn: Connection,
    linter_factory: Callable[[], Any],
    handle: Handler,
    log_path: str,
    settings_env: dict[str, str],
    memory_limit: int | None = None,
    usd_threads: int | None = None,
) -> None:
    """Build the linter (``linter_factory``), say ready, then answer each
    ``(index, item)`` with ``handle(linter, item)`` until ``None``.

    The worker's stderr goes to ``log_path``, emptied before each file: what
    USD prints when it aborts becomes part of the one-line error, not noise
    around the report. ``settings_env`` is the parent's ``USDRENDER_LINT_*``
    environment now: a forkserver child inherits the server's, which may be older.
    ``memory_limit`` caps the worker's data segment (see worker_memory_limit);
    ``usd_threads`` caps USD's thread pool in the worker (see worker_usd_threads).
    """
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
    os.dup2(log, 2)
    os.close(log)
    _off_stdout()
    try:
        from pxr import Usd

        linter = linter_factory()
        # Load USD's plugins and schemas now, so the first file's time limit
        # measures the file, not the start-up.
        Usd.Stage.CreateInMemory()
    except BaseException as exc:  # noqa: BLE001 - reported to the parent, not printed
        debug.show(exc, "a worker could not start")
        conn.send(("failed", f"{type(exc).__name__}: {exc}"))
        return
    conn.send(("ready", None))
    while True:
        try:
            task = conn.recv()
        except (EOFError, OSError):
            return
        if task is None:
            return
        index, item = task
        os.ftruncate(2, 0)
        os.lseek(2, 0, os.SEEK_SET)
        # The result holds only plain values; the stage dies with the handler's frame.
        try:
            result = handle(linter, item)
        except Exception as exc:  # noqa: BLE001 - a handler's bug costs only its item
            debug.show(exc, "internal error")
            result = _Raised(f"internal error: {type(exc).__name__}: {' '.join(str(exc).split())}")
        conn.send((index, result))


@record(frozen=True)
class _Raised:
    """What a worker sends back when its handler raised."""

    why: str


@record
class _Worker:
    process: multiprocessing.process.BaseProcess
    conn: Connection
    #: Where the worker's stderr goes.
    log_path: str
    ready: bool = False
    #: (index, item, deadline) of the item being handled, if any.
    task: tuple[int, Any, float] | None = None
    started: float = 0.0
    linted: int = 0

    def kill(self) -> None:
        if self.process.is_alive():
            self.process.kill()
        self.process.join(5)
        self.conn.close()


class _Pool:
    """A few worker processes fed one file at a time, killed when a file
    runs past the time limit."""

    def __init__(
        self,
        linter_factory: Callable[[], Any],
        size: int,
        timeout: float | None,
        advance: Callable[[], None],
        handle: Handler | None = None,
        failed: OnFailure = file_error,
    ) -> None:
        self._factory = linter_factory
        self._handle = handle or lint_one
        self._failed = failed
        self._size = size
        self._timeout = timeout
        self._memory_limit = worker_memory_limit(size)
        self._usd_threads = worker_usd_threads(size)
        self._advance = advance
        self._context = _context()
        self._workers: list[_Worker] = []
        self._started = 0
        self._log_dir = ""
        self._pending: list[tuple[int, Any]] = []
        self._remaining = 0

    def run(self, files: Sequence[Any]) -> tuple[Any, ...]:
        results: list[Any] = [None] * len(files)
        self._pending = list(reversed(list(enumerate(files))))  # pop() keeps input order
        self._remaining = len(files)
        import shutil
        import tempfile

        self._log_dir = tempfile.mkdtemp(prefix="usdrender-lint-")
        try:
            self._workers = [self._start() for _ in range(self._size)]
            while self._remaining:
                for worker in self._workers:
                    if worker.ready and worker.task is None and self._pending:
                        self._assign(worker, *self._pending.pop())
                self._step(results)
        finally:
            for worker in self._workers:
                self._stop(worker)
            shutil.rmtree(self._log_dir, ignore_errors=True)
        return tuple(results)

    def _start(self) -> _Worker:
        # Chosen per worker: a progress bar's thread makes forking unsafe.
        self._context = _context()
        parent_end, child_end = self._context.Pipe()
        self._started += 1
        log_path = os.path.join(self._log_dir, f"worker-{self._started}.log")
        process = self._context.Process(
            target=_worker_main,
            args=(
                child_end,
                self._factory,
                self._handle,
                log_path,
                _settings_env(),
                self._memory_limit,
                self._usd_threads,
            ),
            daemon=True,
        )
        process.start()
        child_end.close()
        return _Worker(process, parent_end, log_path, started=time.monotonic())

    def _assign(self, worker: _Worker, index: int, item: Any) -> None:
        deadline = time.monotonic() + self._timeout if self._timeout else float("inf")
        worker.task = (index, item, deadline)
        worker.conn.send((index, item))

    def _step(self, results: list[FileResult | None]) -> None:
        """Wait for one message, death or deadline, and handle it."""
        from multiprocessing.connection import wait

        check_stopped()
        handles = [w.conn for w in self._workers] + [w.process.sentinel for w in self._workers]
        ready = set(wait(handles, timeout=self._wait_for()))
        for worker in list(self._workers):
            if worker.conn in ready:
                try:
                    message = worker.conn.recv()
                except (EOFError, OSError):
                    self._replace(worker, results, self._death_message(worker), died=True)
                    continue
                self._receive(worker, message, results)
            elif worker.process.sentinel in ready:
                self._replace(worker, results, self._death_message(worker), died=True)
        self._enforce_deadlines(results)

    def _wait_for(self) -> float | None:
        """Seconds to the nearest deadline (a file's, a starting worker's);
        None: no limit (--timeout 0), wait without a timeout."""
        deadlines = [w.task[2] for w in self._workers if w.task is not None]
        deadlines += [w.started + WORKER_START_LIMIT for w in self._workers if not w.ready]
        nearest = min(deadlines, default=float("inf"))
        return max(0.0, nearest - time.monotonic()) if nearest != float("inf") else None

    def _enforce_deadlines(self, results: list[FileResult | None]) -> None:
        now = time.monotonic()
        for worker in list(self._workers):
            if worker.task is not None and now >= worker.task[2]:
                self._replace(worker, results, _timed_out(self._timeout))
            elif not worker.ready and now >= worker.started + WORKER_START_LIMIT:
                raise ExecutionError(
                    f"a worker process did not start within {WORKER_START_LIMIT:g} s"
                )

    def _receive(self, worker: _Worker, message: tuple, results: list) -> None:
        kind, payload = message
        if kind == "ready":
            worker.ready = True
        elif kind == "failed":
            raise ExecutionError(f"a worker process could not build the linter: {payload}")
        else:
            if isinstance(payload, _Raised) and worker.task is not None:
                payload = self._failed(worker.task[1], payload.why)
            self._done(results, kind, payload)
            worker.task = None
            worker.linted += 1
            if worker.linted >= WORKER_RECYCLE_AFTER and self._pending:
                self._stop(worker)
                self._workers.remove(worker)
                self._workers.append(self._start())

    def _death_message(self, worker: _Worker) -> str:
        worker.process.join(5)
        try:
            with open(worker.log_path, encoding="utf-8", errors="replace") as handle:
                printed = handle.read()
        except OSError:
            printed = ""
        return _crash(worker.process.exitcode, printed)

    def _replace(self, worker: _Worker, results: list, error: str, died: bool = False) -> None:
        """Kill a worker, record its file as an error (or, when it died on a
        file the fast path read, lint that file again fully composed: what
        composing survives, the fast path's walks of the layers may not) and
        start a fresh one."""
        worker.kill()
        self._workers.remove(worker)
        if worker.task is None and not worker.ready:
            raise ExecutionError(f"a worker process died while starting: {error}")
        if worker.task is not None:
            index, item, _ = worker.task
            if died and self._handle is lint_one and isinstance(item, str):
                self._pending.append((index, FullyComposed(item)))
            else:
                self._done(results, index, self._failed(_path_of(item), error))
        if self._pending:
            self._workers.append(self._start())

    def _done(self, results: list, index: int, result: Any) -> None:
        results[index] = result
        self._remaining -= 1
        self._advance()

    def _stop(self, worker: _Worker) -> None:
        try:
            if worker.process.is_alive() and worker.task is None:
                worker.conn.send(None)
                worker.process.join(2)
        except (OSError, ValueError):
            pass
        worker.kill()


def worker_usd_threads(workers: int) -> int | None:
    """USD threads per worker when several share the machine: each its share of
    the cores (at least one), as USD would otherwise start a thread per core in
    every worker and the workers would contend for the cores (measured: 500 small
    shots with --jobs 2 on 2 cores, 1.95 s -> 1.91 s). None (USD's default) for
    one worker, or when the user set ``PXR_WORK_THREAD_LIMIT``."""
    if workers < 2 or os.environ.get("PXR_WORK_THREAD_LIMIT"):
        return None
    return max(1, default_jobs() // workers)


def worker_memory_limit(workers: int) -> int | None:
    """Bytes of data one worker may allocate, so that the workers together stay
    within 90% of the machine's (or container's) memory. A corrupt crate can
    make USD allocate tens of GiB; with a cap the allocation fails at once and
    USD reports ``std::bad_alloc`` for that file instead of exhausting the host."""
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return None
    container = _cgroup_memory_limit()
    if container:
        total = min(total, container)
    return max(MIN_WORKER_MEMORY, int(total * 0.9) // max(workers, 1))


def _cgroup_memory_limit() -> int | None:
    for path in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            text = Path(path).read_text().strip()
        except OSError:
            continue
        if text.isdigit() and int(text) < 1 << 60:  # "max" or a huge number: no limit
            return int(text)
    return None


def _limit_memory(limit: int | None) -> None:
    try:
        import resource
    except ImportError:  # not on Windows
        return
    if limit is None or not hasattr(resource, "RLIMIT_DATA"):
        return
    soft, hard = resource.getrlimit(resource.RLIMIT_DATA)
    if hard != resource.RLIM_INFINITY:
        limit = min(limit, hard)
    if soft == resource.RLIM_INFINITY or limit < soft:
        with suppress(ValueError, OSError):
            resource.setrlimit(resource.RLIMIT_DATA, (limit, hard))


def _off_stdout() -> None:
    """Nothing of a worker's belongs on stdout, and a worker must never hold the
    user's pipe open (``check | tee``) should it outlive the parent."""
    null = os.open(os.devnull, os.O_RDWR)
    os.dup2(null, 0)
    os.dup2(null, 1)
    os.close(null)


def _settings_env() -> dict[str, str]:
    return {name: value for name, value in os.environ.items() if name.startswith(ENV_PREFIX)}


def _last_words(printed: str) -> str:
    """The reason a worker printed before it died: USD's "FATAL ERROR: ..."
    line if there is one, else its last line (one line, at most 200 characters)."""
    lines = [line.strip() for line in printed.splitlines() if line.strip()]
    fatal = [line for line in lines if "FATAL ERROR:" in line]
    if fatal:
        said = "USD " + fatal[-1][fatal[-1].index("FATAL ERROR:") :].replace(
            "FATAL ERROR", "fatal error", 1
        )
    else:
        said = lines[-1] if lines else ""
    return said[:200]
