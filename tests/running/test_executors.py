"""How files are linted is decided once, from the run's jobs, time-out and
supervision (running/workers.py ``choose_executor``); a time-out or a crash of
the supervised child is an input of the run after it, not a module global."""

from __future__ import annotations

import os

import pytest

from usdrender_lint.config import Settings
from usdrender_lint.engine import Linter
from usdrender_lint.running import workers
from usdrender_lint.running.pipeline import LinterSpec
from usdrender_lint.running.result_cache import run_key
from usdrender_lint.running.supervisor import Supervision
from usdrender_lint.testing import all_rules

LINTER = Linter(all_rules())
FACTORY = LinterSpec(Settings())
CHILD = Supervision()  # a child no supervisor times (as tests run the command)


@pytest.mark.parametrize(
    ("count", "jobs", "timeout", "supervision", "kind"),
    [
        (3, 1, None, None, workers.InProcess),  # --jobs 1 --timeout 0, the Python API
        (1, 1, None, CHILD, workers.InProcess),
        (1, 4, 60.0, CHILD, workers.InProcess),  # the lone file of a check: timed by the supervisor
        (2, 4, 60.0, CHILD, workers.Pool),  # more files: a pool, even in the child
        (1, 4, 60.0, None, workers.Pool),  # not supervised: a worker bounds the file
        (5, 2, None, None, workers.Pool),
        (1, 4, 60.0, Supervision(ending="crash"), workers.AfterSupervisedChild),
        (1, 1, None, Supervision(ending="timeout"), workers.AfterSupervisedChild),
        # --jobs 1 --timeout 0 after the child crashed: in this process, the crash was the run's
        (3, 1, None, Supervision(ending="crash"), workers.Pool),
    ],
)
def test_the_executor_is_chosen_once_from_the_run(count, jobs, timeout, supervision, kind):
    chosen = workers.choose_executor(
        count,
        jobs=jobs,
        timeout=timeout,
        supervision=supervision,
        linter=LINTER,
        linter_factory=FACTORY,
    )
    assert type(chosen) is kind
    if isinstance(chosen, workers.InProcess):
        assert chosen.supervision is (CHILD if supervision is CHILD else None)
        assert chosen.timeout == timeout


def test_after_a_time_out_the_file_is_its_error_without_a_second_lint() -> None:
    executor = workers.AfterSupervisedChild("timeout", workers.Pool(FACTORY, 1, 3.0))
    [result] = executor.run(["/no/such/shot.usda"], lambda: None)
    assert result.status == "error"
    assert (
        result.error
        == "/no/such/shot.usda: timed out after 3 s (raise --timeout, or 0 for no limit)"
    )


def test_no_environment_variable_of_ours_enters_the_cache_key(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    before = run_key(LINTER, Settings())
    for name in ("USDRENDER_LINT_NO_SUPERVISOR", "USDRENDER_LINT_DEBUG", "USDRENDER_LINT_X"):
        monkeypatch.setenv(name, "1")
    assert run_key(LINTER, Settings()) == before
    monkeypatch.setenv("PXR_AR_DEFAULT_SEARCH_PATH", "/elsewhere")  # USD's own: it composes
    assert run_key(LINTER, Settings()) != before


def test_a_worker_that_dies_while_starting_says_so_in_one_line(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # It read "a worker process died while starting: the linter process crashed
    # while reading it (signal SIGSEGV)" (USD's start under a tight ulimit -v).
    monkeypatch.setattr("usdrender_lint.running.address_space.address_space_limit", lambda: None)
    with pytest.raises(workers.ExecutionError) as raised:
        workers.Pool(os.abort, 1, None).run(["/no/such/shot.usda"])
    assert str(raised.value) == "a worker process died while starting (signal SIGABRT)"


def test_a_worker_that_dies_while_starting_names_the_address_space_limit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Between about 512 MiB and 1 GiB of ``ulimit -v`` USD loads in the command
    and its worker dies starting (SIGSEGV): the line said nothing of the limit."""
    monkeypatch.setattr(
        "usdrender_lint.running.address_space.address_space_limit", lambda: 900 << 20
    )
    with pytest.raises(workers.ExecutionError) as raised:
        workers.Pool(os.abort, 1, None).run(["/no/such/shot.usda"])
    assert str(raised.value) == (
        "a worker process died while starting (signal SIGABRT); "
        "the address-space limit (ulimit -v) is 900 MiB: raise it"
    )
