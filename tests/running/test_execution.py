"""How files are executed: worker processes, per-file time limit, crash
isolation, deterministic order, progress only on a terminal."""

from __future__ import annotations

import io
import os
import select
import signal
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

import pytest
from click.testing import CliRunner
from pxr import Sdf, UsdGeom

from usdrender_lint.api import Diagnostic, Rule, Severity
from usdrender_lint.cli import cli
from usdrender_lint.config import Settings
from usdrender_lint.engine import Linter
from usdrender_lint.model import FileResult, Report
from usdrender_lint.running import workers as execution
from usdrender_lint.running.discovery import collect_files
from usdrender_lint.running.pipeline import LinterSpec, make_linter
from usdrender_lint.running.progress import PROGRESS_MIN_FILES, want_progress
from usdrender_lint.running.workers import ExecutionError, lint_paths

pytestmark = pytest.mark.heavy(seconds=27)

_T = TypeVar("_T")
SCOPE = '#usda 1.0\ndef Scope "{name}"\n{{\n}}\n'
SETTINGS = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "S"
    {
        uniform float4 dataWindowNDC = (1, 1, 0, 0)
    }
}
"""


class TrapRule(Rule):
    """Test-only rule: misbehaves on Scopes with special names.

    ## What it does
    Crashes the process on a Scope named Crash, hangs on one named Hang, on one
    named Threads says how many Python threads its process runs, on one
    named Peek waits up to 10 s for the worker's connection to the parent (its one
    socket) to hold the next file and says whether it did, and otherwise reports
    every Scope.
    """

    code = "TX901"
    name = "test-trap"
    severity = Severity.WARNING
    prim_types = (UsdGeom.Scope,)

    def check_prim(self, prim, ctx):
        if prim.GetName() == "Crash":
            os.kill(os.getpid(), signal.SIGSEGV)
        if prim.GetName() == "Hang":
            time.sleep(3600)
        if prim.GetName() == "Abort":
            # What USD does on a TF_FATAL_ERROR: a banner on stderr, then abort().
            os.write(2, b"\n---- python3.11 terminated ----\n")
            os.write(2, b"python3.11 crashed. FATAL ERROR: Dereferenced an invalid spec\n")
            os.abort()
        if prim.GetName() == "Threads":
            yield Diagnostic(message=f"python threads: {threading.active_count()}", at=prim)
            return
        if prim.GetName() == "Peek":
            # Waiting in the worker's pipe (workers.IN_FLIGHT).
            fds = [fd for fd in map(int, os.listdir("/proc/self/fd")) if _is_socket(fd)]
            deadline = time.monotonic() + 10
            ready: list = []
            while not ready and time.monotonic() < deadline:
                ready = select.select(fds, [], [], 0.01)[0]
            yield Diagnostic(message=f"next file waiting: {bool(ready)}", at=prim)
            return
        yield Diagnostic(message=f"scope {prim.GetName()}", at=prim)


def trap_linter() -> Linter:
    return Linter([TrapRule()])


class ProcessRule(Rule):
    """Test-only rule: reports the id of the process that lints.

    ## What it does
    Reports each Scope with ``os.getpid()``.
    """

    code = "TX904"
    name = "test-process"
    severity = Severity.INFO
    prim_types = (UsdGeom.Scope,)

    def check_prim(self, prim, ctx):
        yield Diagnostic(message=f"pid {os.getpid()}", at=prim)


def process_linter() -> Linter:
    return Linter([ProcessRule()])


def _is_socket(fd: int) -> bool:
    try:
        return os.readlink(f"/proc/self/fd/{fd}").startswith("socket:")
    except OSError:  # the listing's own descriptor, closed since
        return False


def broken_factory() -> Linter:
    raise RuntimeError("plugin acme failed to import")


def _within(seconds: int, call: Callable[[], _T]) -> _T:
    """``call()``, failing the test (TimeoutError) when it takes longer than ``seconds``."""

    def expire(signum: int, frame: object) -> None:
        raise TimeoutError(f"no answer within {seconds} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(seconds)
    try:
        return call()
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def _write(folder: Path, name: str, text: str) -> str:
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return str(path)


@pytest.fixture
def mixed_files(tmp_path: Path) -> list[str]:
    """Clean, failing, unparsable and missing inputs, deliberately unsorted."""
    return [
        _write(tmp_path, "b_settings.usda", SETTINGS),
        _write(tmp_path, "a_scope.usda", SCOPE.format(name="A")),
        _write(tmp_path, "c_broken.usda", '#usda 1.0\ndef Scope "X" {\n'),
        str(tmp_path / "d_missing.usda"),
        _write(tmp_path, "e_settings.usda", SETTINGS),
    ]


def test_workers_give_the_in_process_results_in_input_order(mixed_files: list[str]) -> None:
    settings = Settings()
    linter = make_linter(settings)
    alone = Report(execution.lint_paths(mixed_files, linter=linter))
    pooled = Report(
        execution.lint_paths(mixed_files, linter_factory=LinterSpec(settings), jobs=2, timeout=60)
    )
    assert [r.file for r in pooled.files] == mixed_files
    assert pooled == alone
    statuses = [r.status for r in pooled.files]
    assert statuses == ["linted", "linted", "linted", "error", "linted"]
    assert {f.code for f in pooled.files[0].findings} >= {"SE003"}
    assert [f.code for f in pooled.files[2].findings] == ["ST001"]


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_file_past_the_time_limit_is_an_error_and_the_rest_are_linted(
    tmp_path: Path, jobs: int
) -> None:
    # With one worker, file 3 waits in its pipe behind the hung file 2 (IN_FLIGHT).
    files = [
        _write(tmp_path, "1.usda", SCOPE.format(name="One")),
        _write(tmp_path, "2.usda", SCOPE.format(name="Hang")),
        _write(tmp_path, "3.usda", SCOPE.format(name="Three")),
        _write(tmp_path, "4.usda", SCOPE.format(name="Four")),
    ]
    started = time.monotonic()
    results = lint_paths(files, linter_factory=trap_linter, jobs=jobs, timeout=2.5)
    assert time.monotonic() - started < 30
    assert [r.status for r in results] == ["linted", "error", "linted", "linted"]
    assert (
        results[1].error == f"{files[1]}: timed out after 2.5 s in rule TX901 (test-trap) "
        "(raise --timeout, or 0 for no limit)"
    )
    assert [f.message for f in results[3].findings] == ["scope Four"]


@pytest.mark.parametrize("crash_at", [0, 1])
def test_a_worker_that_crashes_costs_only_its_file(tmp_path: Path, crash_at: int) -> None:
    # The file after the crashing one waits in the worker's pipe (IN_FLIGHT): it
    # is linted by the next worker, not lost with this one.
    names = ["One", "Two", "Three"]
    names[crash_at] = "Crash"
    files = [_write(tmp_path, f"{n}.usda", SCOPE.format(name=name)) for n, name in enumerate(names)]
    results = lint_paths(files, linter_factory=trap_linter, jobs=1, timeout=60)
    assert results[crash_at].status == "error"
    assert results[crash_at].error == (
        f"{files[crash_at]}: the linter process crashed while reading it (signal SIGSEGV)"
    )
    assert [[f.message for f in r.findings] for r in results if r.status == "linted"] == [
        [f"scope {name}"] for name in names if name != "Crash"
    ]


def test_a_worker_holds_the_next_file_while_it_lints_one(tmp_path: Path) -> None:
    """So that it never waits for the parent between files (workers.IN_FLIGHT)."""
    files = [
        _write(tmp_path, "1.usda", SCOPE.format(name="Peek")),
        _write(tmp_path, "2.usda", SCOPE.format(name="Two")),
    ]
    results = lint_paths(files, linter_factory=trap_linter, jobs=1, timeout=60)
    assert [f.message for f in results[0].findings] == ["next file waiting: True"]


def test_a_worker_of_jobs_1_lints_on_one_thread_however_many_cores(tmp_path: Path) -> None:
    """--jobs 1 is one core's work: no thread of the worker reads the next file
    ahead on a core the run was not given (docs/guides/performance.md)."""
    files = [
        _write(tmp_path, "1.usda", SCOPE.format(name="Threads")),
        _write(tmp_path, "2.usda", SCOPE.format(name="Two")),
    ]
    results = lint_paths(files, linter_factory=trap_linter, jobs=1, timeout=60)
    assert [f.message for f in results[0].findings] == ["python threads: 1"]


def test_what_a_dying_worker_prints_becomes_the_one_line_error(
    tmp_path: Path, capfd: pytest.CaptureFixture
) -> None:
    files = [
        _write(tmp_path, "1.usda", SCOPE.format(name="Abort")),
        _write(tmp_path, "2.usda", SCOPE.format(name="Two")),
    ]
    results = lint_paths(files, linter_factory=trap_linter, jobs=2, timeout=60)
    assert results[0].error == (
        f"{files[0]}: the linter process crashed while reading it "
        "(signal SIGABRT: USD fatal error: Dereferenced an invalid spec)"
    )
    assert [f.message for f in results[1].findings] == ["scope Two"]
    captured = capfd.readouterr()
    assert "FATAL" not in captured.err and "terminated" not in captured.err


def test_every_worker_is_killed_before_any_is_joined(
    mixed_files: list[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """At the end of a run the workers exit side by side, not one after another."""
    from multiprocessing.process import BaseProcess

    events: list[tuple[str, int | None]] = []
    kill, join = BaseProcess.kill, BaseProcess.join

    def recorded_kill(process: BaseProcess) -> None:
        events.append(("kill", process.pid))
        kill(process)

    def recorded_join(process: BaseProcess, timeout: float | None = None) -> None:
        events.append(("join", process.pid))
        join(process, timeout)

    monkeypatch.setattr(BaseProcess, "kill", recorded_kill)
    monkeypatch.setattr(BaseProcess, "join", recorded_join)
    results = lint_paths(mixed_files, linter_factory=LinterSpec(Settings()), jobs=2, timeout=60)
    assert len(results) == len(mixed_files)
    first_join = next(i for i, (what, _) in enumerate(events) if what == "join")
    killed = {pid for what, pid in events[:first_join] if what == "kill"}
    assert len(killed) == 2
    assert killed == {pid for what, pid in events if what == "join"}


def test_workers_have_the_kernel_read_each_file_as_it_is_sent(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The parent asks for each file as it hands it to a worker, in input order.
    files = [_write(tmp_path, f"{n}.usda", SCOPE.format(name=f"S{n}")) for n in range(3)]
    asked: list[str] = []
    monkeypatch.setattr(execution, "will_read", asked.append)
    results = lint_paths(files, linter_factory=LinterSpec(Settings()), jobs=1, timeout=60)
    assert [r.status for r in results] == ["linted"] * 3
    assert asked == files


def test_in_process_the_next_file_is_asked_for_before_this_one_is_linted(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    files = [_write(tmp_path, f"{n}.usda", SCOPE.format(name=f"S{n}")) for n in range(3)]
    events: list[tuple[str, str]] = []
    monkeypatch.setattr(execution, "will_read", lambda path: events.append(("asked", path)))
    linter = make_linter(Settings())
    real = linter.lint_path

    def lint_path(path: str, *, full_composition: bool = False) -> FileResult:
        events.append(("linted", path))
        return real(path, full_composition=full_composition)

    monkeypatch.setattr(linter, "lint_path", lint_path)
    lint_paths(files, linter=linter, jobs=1)
    assert events == [
        ("asked", files[1]),
        ("linted", files[0]),
        ("asked", files[2]),
        ("linted", files[1]),
        ("linted", files[2]),
    ]


def test_will_read_advises_regular_files_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    advised: list[tuple[int, int, int]] = []
    monkeypatch.setattr(
        os,
        "posix_fadvise",
        lambda fd, start, length, advice: advised.append((start, length, advice)),
        raising=False,
    )
    monkeypatch.setattr(execution, "WILL_READ_BYTES", 4)
    shot = tmp_path / "shot.usda"
    shot.write_text(SCOPE.format(name="S"))
    fifo = tmp_path / "fifo.usda"
    os.mkfifo(fifo)  # opened without blocking: the call returns at once
    for path in (shot, fifo, tmp_path, tmp_path / "missing.usda"):
        execution.will_read(str(path))
    assert advised == [(0, 4, os.POSIX_FADV_WILLNEED)]


def test_long_runs_recycle_workers(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(execution, "WORKER_RECYCLE_AFTER", 2)
    files = [_write(tmp_path, f"{n}.usda", SCOPE.format(name=f"S{n}")) for n in range(5)]
    results = lint_paths(files, linter_factory=process_linter, jobs=1, timeout=60)
    pids = [r.findings[0].message for r in results]
    assert pids[0] == pids[1] != pids[2] == pids[3] != pids[4]
    assert str(os.getpid()) not in " ".join(pids)


@pytest.mark.parametrize("crash_at", [1, 2])
def test_a_crash_around_a_recycling_loses_no_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, crash_at: int
) -> None:
    # With a worker recycled every 2 files, the crash lands on its last file (1) or on
    # the next worker's first (2); the file queued behind it goes to the next worker.
    monkeypatch.setattr(execution, "WORKER_RECYCLE_AFTER", 2)
    names = [f"S{n}" for n in range(5)]
    names[crash_at] = "Crash"
    files = [_write(tmp_path, f"{n}.usda", SCOPE.format(name=name)) for n, name in enumerate(names)]
    # A file lost from the pool would leave it waiting for an answer forever.
    results = _within(60, lambda: lint_paths(files, linter_factory=trap_linter, jobs=1, timeout=60))
    said = [r.findings[0].message if r.status == "linted" else r.status for r in results]
    assert said == ["error" if name == "Crash" else f"scope {name}" for name in names]


def test_a_file_sent_to_a_worker_that_just_died_is_linted_by_the_next(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # On a loaded machine the worker can crash on one file before the parent sends
    # it the next: that send fails (a broken pipe), and the file goes to the next
    # worker. Here the parent pauses after sending the crashing file, as load would.
    names = ["Crash", "S1", "S2"]
    files = [_write(tmp_path, f"{n}.usda", SCOPE.format(name=name)) for n, name in enumerate(names)]
    sent = []

    def paused(path: str) -> None:
        sent.append(path)
        if path == files[0]:
            time.sleep(1.0)  # the worker crashes meanwhile

    monkeypatch.setattr(execution, "will_read", paused)
    results = _within(60, lambda: lint_paths(files, linter_factory=trap_linter, jobs=1, timeout=60))
    said = [r.findings[0].message if r.status == "linted" else r.status for r in results]
    assert said == ["error", "scope S1", "scope S2"]
    assert sent.count(files[1]) == 1  # the failed send is no read ahead


def test_a_worker_that_cannot_build_its_linter_stops_the_run(tmp_path: Path) -> None:
    files = [_write(tmp_path, "1.usda", SCOPE.format(name="A"))]
    with pytest.raises(ExecutionError, match="plugin acme failed to import"):
        lint_paths(files, linter_factory=broken_factory, jobs=2, timeout=10)


def test_in_process_an_engine_failure_on_one_file_does_not_stop_the_others(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    files = [_write(tmp_path, f"{n}.usda", SCOPE.format(name=f"S{n}")) for n in range(3)]
    linter = trap_linter()
    real = linter.lint_path

    def flaky(path: str, *, full_composition: bool = False) -> FileResult:
        if path == files[1]:
            raise MemoryError("out of memory")
        return real(path, full_composition=full_composition)

    monkeypatch.setattr(linter, "lint_path", flaky)
    results = lint_paths(files, linter=linter)
    assert [r.status for r in results] == ["linted", "error", "linted"]
    assert results[1].error == f"{files[1]}: internal error: MemoryError: out of memory"


def test_no_stage_outlives_its_file(tmp_path: Path) -> None:
    path = _write(tmp_path, "settings.usda", SETTINGS)
    result = lint_paths([path], linter=make_linter(Settings()))[0]
    assert result.findings
    # Sdf keeps a layer only while something (a stage) holds it.
    assert not Sdf.Layer.Find(path)


def test_progress_only_on_a_terminal_and_for_many_files(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("sys.stderr", io.StringIO())
    assert not want_progress(500)
    assert want_progress(3, asked=True)  # --progress
    monkeypatch.setattr("sys.stderr.isatty", lambda: True)
    assert want_progress(PROGRESS_MIN_FILES + 1)
    assert not want_progress(PROGRESS_MIN_FILES)
    assert not want_progress(500, asked=False)  # --no-progress


def test_progress_bar_draws_on_stderr_only(
    tmp_path: Path, capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("FORCE_COLOR", "1")  # rich then draws as on a terminal
    files = [_write(tmp_path, f"{n}.usda", SCOPE.format(name=f"S{n}")) for n in range(3)]
    lint_paths(files, linter=trap_linter(), progress=True)
    captured = capsys.readouterr()
    assert captured.out == ""
    assert "3/3" in captured.err


def test_cli_jobs_output_is_identical_to_one_job(mixed_files: list[str]) -> None:
    runner = CliRunner()
    base = ["check", "--isolated", "--format", "json"]
    one = runner.invoke(cli, [*base, "--jobs", "1", "--timeout", "0", *mixed_files])
    two = runner.invoke(cli, [*base, "--jobs", "2", *mixed_files])
    assert one.exit_code == two.exit_code == 2
    assert one.stdout == two.stdout
    assert one.stderr == two.stderr == f"usdrender-lint: error: {mixed_files[3]}: no such file\n"


def test_cli_rejects_zero_jobs(tmp_path: Path) -> None:
    path = _write(tmp_path, "a.usda", SCOPE.format(name="A"))
    result = CliRunner().invoke(cli, ["check", "--jobs", "0", path])
    assert result.exit_code == 2
    assert "--jobs" in result.stderr


def test_real_files_give_the_same_report_with_workers(shared_dir: Path) -> None:
    """Public USD files from ../shared/corpus: a worker pool with a time limit
    reports exactly what one process does."""
    files = collect_files([str(shared_dir / "corpus" / "files")])[:60]
    assert files
    settings = Settings()
    linter = make_linter(settings)
    alone = Report(execution.lint_paths(files, linter=linter))
    pooled = Report(
        execution.lint_paths(files, linter_factory=LinterSpec(settings), jobs=2, timeout=120)
    )
    assert pooled == alone
    assert not pooled.errored_files
    assert all(f.code != "UL000" for f in pooled.findings)


def test_workers_without_a_time_limit(mixed_files: list[str]) -> None:
    """--jobs 2 --timeout 0: workers wait with no deadline (no infinite timeout
    handed to the selector)."""
    runner = CliRunner()
    base = ["check", "--isolated", "--format", "json"]
    one = runner.invoke(cli, [*base, "--jobs", "1", "--timeout", "0", *mixed_files])
    two = runner.invoke(cli, [*base, "--jobs", "2", "--timeout", "0", *mixed_files])
    assert two.exit_code == one.exit_code == 2
    assert two.stdout == one.stdout


def _nothing_to_build() -> None:
    return None


def _usd_threads(built: None, item: str) -> int:
    from pxr import Work

    return Work.GetConcurrencyLimit()


def _slow_pid(built: None, item: str) -> int:
    time.sleep(1.0)  # long past the second worker's start
    return os.getpid()


def test_as_many_files_as_workers_go_one_to_each() -> None:
    """A worker is sent a next file only while more wait than there are other
    workers: two files on two workers were both held by the first one ready, and
    ran one after the other."""
    pool = execution.Pool(_nothing_to_build, 2, None, handle=_slow_pid)
    first, second = pool.run(["one", "two"])
    assert first != second


@pytest.mark.parametrize("size", [1, 2, 3])
def test_workers_share_the_cores_for_usd_threads(
    size: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each of N workers lets USD use its share of the cores (at least one)."""
    from pxr import Work

    monkeypatch.delenv("PXR_WORK_THREAD_LIMIT", raising=False)
    own = Work.GetConcurrencyLimit()
    pool = execution.Pool(_nothing_to_build, size, None, handle=_usd_threads)
    threads = pool.run([f"item {n}" for n in range(size)])
    share = max(1, Work.GetPhysicalConcurrencyLimit() // size)
    assert set(threads) == {own if size == 1 else min(own, share)}


@pytest.mark.parametrize("user_limit", [None, "0"])
def test_a_usd_thread_limit_the_user_set_stands(user_limit: str | None) -> None:
    """With PXR_WORK_THREAD_LIMIT set (0: every core), a worker keeps USD's limit.
    In a process of its own: a forkserver's workers have the server's environment."""
    import subprocess
    import sys

    env = {k: v for k, v in os.environ.items() if k != "PXR_WORK_THREAD_LIMIT"}
    if user_limit is not None:
        env["PXR_WORK_THREAD_LIMIT"] = user_limit
    code = (
        "from pxr import Work; from usdrender_lint.running.workers import share_cores; "
        "before = Work.GetConcurrencyLimit(); share_cores(2); "
        "print(before, Work.GetConcurrencyLimit(), Work.GetPhysicalConcurrencyLimit())"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    before, after, cores = map(int, done.stdout.split())
    assert after == (before if user_limit is not None else min(before, max(1, cores // 2)))
