"""One file under a time limit is linted in a forked child of the process
(running/workers.py ``_lint_in_child``), not in a worker pool: the same result,
the same one-line errors for a hang or a crash. Each case runs in a fresh
process, as the command line does: only a process that runs one thread forks
(a test process has USD's threads running)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

SCOPE = '#usda 1.0\ndef Scope "{name}"\n{{\n}}\n'

SCRIPT = """
import json, os, signal, sys, time
from pxr import UsdGeom
from usdrender_lint.api import Diagnostic, Rule, Severity
from usdrender_lint.engine import Linter
from usdrender_lint.running import workers


class ChildTrap(Rule):
    '''Test-only rule: reports the process id on every Scope; crashes on one
    named Crash, hangs on Hang, prints USD's fatal error banner and aborts on Abort.'''

    code = "TX911"
    name = "test-child-trap"
    severity = Severity.INFO
    prim_types = (UsdGeom.Scope,)

    def check_prim(self, prim, ctx):
        if prim.GetName() == "Crash":
            os.kill(os.getpid(), signal.SIGSEGV)
        if prim.GetName() == "Hang":
            time.sleep(3600)
        if prim.GetName() == "Abort":
            os.write(2, b"noise\\n" * 20_000)  # more than a pipe holds: must not block
            os.write(2, b"python3.11 crashed. FATAL ERROR: Dereferenced an invalid spec\\n")
            os.abort()
        yield Diagnostic(message=f"pid {os.getpid()}", at=prim)


def refuse(*args, **kwargs):
    raise AssertionError("one file must not start a worker pool")


if sys.argv[3] == "no-pool":
    workers._Pool = refuse
else:
    workers._can_fork = lambda: False  # the worker pool, for comparison
factory = (lambda: Linter([ChildTrap()])) if sys.argv[4] == "ok" else None
if factory is None:
    def factory():
        raise ImportError("plugin acme failed to import")
try:
    [result] = workers.lint_paths([sys.argv[1]], linter_factory=factory, jobs=2,
                                  timeout=float(sys.argv[2]))
except workers.ExecutionError as exc:
    print(json.dumps({"raised": str(exc)}))
else:
    print(json.dumps({"parent": os.getpid(), "status": result.status, "error": result.error,
                      "messages": [f.message for f in result.findings]}))
"""


def _run(path: Path, timeout: float = 60, pool: str = "no-pool", factory: str = "ok") -> dict:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    proc = subprocess.run(
        [sys.executable, "-c", SCRIPT, str(path), str(timeout), pool, factory],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert "noise" not in proc.stderr
    return json.loads(proc.stdout)


def _file(tmp_path: Path, name: str) -> Path:
    path = tmp_path / f"{name}.usda"
    path.write_text(SCOPE.format(name=name))
    return path


def test_the_child_lints_the_file(tmp_path: Path) -> None:
    done = _run(_file(tmp_path, "Fine"))
    assert done["status"] == "linted"
    [message] = done["messages"]
    assert message.startswith("pid ") and message != f"pid {done['parent']}"


def test_a_hang_is_killed_at_the_time_limit(tmp_path: Path) -> None:
    path = _file(tmp_path, "Hang")
    started = time.monotonic()
    done = _run(path, timeout=1.5)
    assert time.monotonic() - started < 60
    assert done["status"] == "error"
    assert done["error"] == f"{path}: timed out after 1.5 s (raise --timeout, or 0 for no limit)"


def test_a_crash_costs_only_the_file(tmp_path: Path) -> None:
    path = _file(tmp_path, "Crash")
    assert _run(path)["error"] == (
        f"{path}: the linter process crashed while reading it (signal SIGSEGV)"
    )


def test_what_the_child_printed_before_it_died_is_the_reason(tmp_path: Path) -> None:
    path = _file(tmp_path, "Abort")
    assert _run(path)["error"] == (
        f"{path}: the linter process crashed while reading it "
        "(signal SIGABRT: USD fatal error: Dereferenced an invalid spec)"
    )


def test_a_factory_that_fails_stops_the_run(tmp_path: Path) -> None:
    done = _run(_file(tmp_path, "Fine"), factory="broken")
    assert "could not build the linter" in done["raised"] and "acme" in done["raised"]


@pytest.mark.parametrize("timeout", [0, 60])
def test_the_result_is_the_one_the_pool_gives(tmp_path: Path, timeout: float) -> None:
    path = _file(tmp_path, "Fine")
    child, pool = _run(path, timeout=timeout), _run(path, timeout=timeout, pool="pool")
    assert child["status"] == pool["status"] == "linted"
    assert len(child["messages"]) == len(pool["messages"]) == 1
