from __future__ import annotations

import os
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

TESTS = Path(__file__).parent
REPO = TESTS.parent
#: ../shared beside the project: present on developer machines and in CI only.
SHARED = Path(os.environ.get("USDRENDER_LINT_SHARED", REPO.parent / "shared"))
SHARED_MISSING = "../shared is not present (only on developer machines and in CI)"


@pytest.fixture(autouse=True, scope="session")
def _no_result_cache_in_session_fixtures(
    tmp_path_factory: pytest.TempPathFactory,
) -> Iterator[None]:
    """The module and session fixtures (which run before any function-scoped
    one) lint without a cache too: else a report they make (the HTML pages of
    the corpus) stores entries in the checkout, which a later run, or the other
    xdist worker, reads back instead of linting."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("USDRENDER_LINT_NO_CACHE", "1")
        # The user's own configuration (~/.config/usdrender-lint) would change
        # what a test with no project configuration sees: none is read.
        empty = tmp_path_factory.mktemp("user-config")
        patch.setenv("XDG_CONFIG_HOME", str(empty))
        patch.setenv("APPDATA", str(empty))
        yield


@pytest.fixture(autouse=True, scope="session")
def _no_thread_left_busy() -> Iterator[None]:
    """Once this worker's tests ended, no thread of theirs still runs
    (thread_support.busy_threads): one left looping takes a core from every
    later test, and from the other workers."""
    yield
    from thread_support import busy_threads

    busy = busy_threads()
    assert not busy, f"threads still running after the tests ended: {busy}"


@pytest.fixture(autouse=True)
def _no_result_cache(monkeypatch: pytest.MonkeyPatch) -> None:
    """Tests lint with a fresh engine every time (tests/running/test_result_cache.py
    turns the cache on for itself): a result reused from an earlier test would
    hide what a test changed in the engine or its rules."""
    monkeypatch.setenv("USDRENDER_LINT_NO_CACHE", "1")


@pytest.fixture(autouse=True)
def _lint_start_on_the_precise_clock(monkeypatch: pytest.MonkeyPatch) -> None:
    """A test writes a layer and lints it in the same process microseconds later,
    inside the clock tick the result cache takes as the lint's start
    (result_cache.lint_start_ns), which counts such a layer as changed during the
    lint and stores nothing: a user's files are older than the command's
    start-up. Tests start on the precise clock; the coarse one is tested in
    tests/running/test_cache_changes_while_linting.py."""
    import time

    from usdrender_lint.running import result_cache

    monkeypatch.setattr(result_cache, "lint_start_ns", time.time_ns)


@pytest.fixture(autouse=True)
def _signal_handlers_restored(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """A test that imports the command's entry point in this process installs
    its signal handlers (running/interrupts.py; test_startup's memory-error
    test did), and they stayed for every later test of the worker: a signal
    then raised Stopped in whatever test ran and left this process ignoring
    SIGINT, SIGTERM and SIGHUP, which each command a later test started would
    inherit (a command started ignoring a signal keeps ignoring it)."""
    import signal

    from usdrender_lint.running import interrupts

    kept = [*interrupts.STOPPING, signal.SIGCONT]
    handlers = {signum: signal.getsignal(signum) for signum in kept}
    monkeypatch.setattr(interrupts, "_received", interrupts._received)
    monkeypatch.setattr(sys, "unraisablehook", sys.unraisablehook)
    yield
    for signum, handler in handlers.items():
        signal.signal(signum, handler)


@pytest.fixture
def shared_dir() -> Path:
    if not SHARED.is_dir():
        pytest.skip(SHARED_MISSING)
    return SHARED


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """``-n auto``: one worker more than the cores this process may use. Many
    tests wait (a command's time-out, a signal, a language server's answer), so
    with one worker per core the cores idled: on 2 cores the suite kept them
    166% busy of 200% (743 s), with a third worker 177% (673 s), measured while
    a test helper's reader threads spun (tests/server/lsp_editor.py, since
    fixed: the suite now takes 360 to 410 s with three)."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return (cores or 1) + 1


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The files marked ``heavy`` first, the longest first (the mark's
    ``seconds``, measured with ``--durations`` on 2 cores): xdist hands files out
    in collection order (``--no-loadscope-reorder``), so a long file collected
    late would run alone while the other worker sits idle."""
    items.sort(key=_heaviness)  # stable: every other file keeps its order


def _heaviness(item: pytest.Item) -> float:
    mark = item.get_closest_marker("heavy")
    return -float(mark.kwargs["seconds"]) if mark is not None else 0.0


@pytest.hookimpl(wrapper=True, tryfirst=True)
def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter) -> Iterator[None]:
    """One line, just above pytest's closing one, for a plain clone: how many
    tests skipped because ../shared (the real-file corpus, the rule catalog) is
    not there, and where the contributing guide says what they cover. (The
    outermost wrapper: after the short test summary that ``-ra`` prints.)"""
    yield
    skipped = [
        report
        for report in terminalreporter.stats.get("skipped", [])
        if SHARED_MISSING in str(getattr(report, "longrepr", ""))
    ]
    if skipped:
        count = f"{len(skipped)} test{'s' if len(skipped) != 1 else ''}"
        terminalreporter.write_line(
            f"{count} skipped for want of ../shared (the real-file corpus and the rule "
            "catalog): see 'Tests that need ../shared' in docs/contributing.md"
        )
