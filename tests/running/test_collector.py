"""The command's processes collect cyclic garbage less often (running/collector.py):
a lint makes none, and each collection during one walked its objects for nothing."""

from __future__ import annotations

import gc
import subprocess
import sys
import threading
from collections.abc import Iterator

import pytest

from usdrender_lint.running import workers
from usdrender_lint.running.collector import LINT_THRESHOLD, collect_less_often


@pytest.fixture
def threshold() -> Iterator[None]:
    saved = gc.get_threshold()
    yield
    gc.set_threshold(*saved)


def test_the_youngest_generation_is_collected_after_the_lint_threshold(threshold: None) -> None:
    gc.set_threshold(700, 10, 10)
    collect_less_often()
    assert gc.get_threshold() == (LINT_THRESHOLD, 10, 10)


@pytest.mark.parametrize("set_before", [(0, 10, 10), (LINT_THRESHOLD * 2, 5, 5)])
def test_a_collector_that_is_off_or_collects_less_often_is_left_alone(
    threshold: None, set_before: tuple[int, int, int]
) -> None:
    gc.set_threshold(*set_before)
    collect_less_often()
    assert gc.get_threshold() == set_before


def test_the_command_sets_its_own_process_once_the_engine_is_imported() -> None:
    shown = subprocess.run(
        [
            sys.executable,
            "-c",
            "import gc; from usdrender_lint.cli.loading import import_engine; "
            "before = gc.get_threshold()[0]; import_engine(); print(before, gc.get_threshold()[0])",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert shown.stdout.split() == ["700", str(LINT_THRESHOLD)]


def test_a_host_that_imports_the_api_keeps_its_collector() -> None:
    shown = subprocess.run(
        [
            sys.executable,
            "-c",
            "import gc, usdrender_lint; from usdrender_lint.running import pipeline; "
            "print(gc.get_threshold()[0])",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert shown.stdout.split() == ["700"]


def threshold_of_worker(linter: object, item: str) -> tuple[int, ...]:
    """A Pool handler that answers with the worker's collector threshold."""
    return gc.get_threshold()


@pytest.mark.parametrize("with_a_thread", [False, True], ids=["as-is", "with-a-thread"])
def test_a_worker_collects_less_often_however_it_was_started(
    threshold: None, with_a_thread: bool
) -> None:
    """Forked from this process (which has 700), or started by a fork server
    when this process has a thread (a progress bar's), the worker sets its own."""
    gc.set_threshold(700, 10, 10)
    stop = threading.Event()
    waiting = threading.Thread(target=stop.wait, daemon=True)
    if with_a_thread:
        waiting.start()
    try:
        pool = workers.Pool(object, 1, None, handle=threshold_of_worker)
        [answer] = pool.run(["shot.usda"])
    finally:
        stop.set()
        if with_a_thread:
            waiting.join()
    assert answer[0] == LINT_THRESHOLD
    assert gc.get_threshold()[0] == 700  # the pool leaves its own process's as it was
