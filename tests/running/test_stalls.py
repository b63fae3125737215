"""A time-out names where the lint was: the rule whose hook ran, or the step (USD
opening the stage), alike on every path that times a file."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.cli_support import command, hanging_stage
from usdrender_lint.engine import linter, stage
from usdrender_lint.running import stalls
from usdrender_lint.running.workers import timed_out

pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="supervised runs: Linux"),
    pytest.mark.heavy(seconds=27),
]

HANGING_RULE = '''
import time
from pxr import UsdRender
from usdrender_lint.api import Rule, Severity


class Hanging(Rule):
    """Never returns.

    ## What it does
    Test rule.
    """

    code = "HNG001"
    name = "hanging-rule"
    severity = Severity.WARNING
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim, ctx):
        while True:
            time.sleep(0.05)
        yield from ()


RULES = [Hanging]
'''
SHOT = """#usda 1.0

def Scope "Render"
{
    def RenderSettings "Settings"
    {
    }
}
"""


def _plugin(tmp_path: Path) -> dict[str, str]:
    site = tmp_path / "site"
    (site / "hanging-0.1.dist-info").mkdir(parents=True)
    (site / "hanging.py").write_text(HANGING_RULE)
    (site / "hanging-0.1.dist-info" / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: hanging\nVersion: 0.1\n"
    )
    (site / "hanging-0.1.dist-info" / "entry_points.txt").write_text(
        "[usdrender_lint.rules]\nhanging = hanging:RULES\n"
    )
    return {**os.environ, "PYTHONPATH": str(site), "USDRENDER_LINT_NO_CACHE": "1"}


def _stderr(tmp_path: Path, *args: str, env: dict[str, str], stdin: str | None = None) -> str:
    done = subprocess.run(
        command("check", "--isolated", "--timeout", "2", *args),
        cwd=tmp_path,
        env=env,
        input=stdin,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 2, done.stderr
    return done.stderr


def test_a_time_out_names_the_rule_that_hung_on_every_path(tmp_path: Path) -> None:
    env = _plugin(tmp_path)
    (tmp_path / "a.usda").write_text(SHOT)
    (tmp_path / "b.usda").write_text(SHOT)
    why = "timed out after 2 s in rule HNG001 (hanging-rule) (raise --timeout, or 0 for no limit)"
    lone = _stderr(tmp_path, "a.usda", env=env)  # the supervisor times the child
    assert lone == f"usdrender-lint: error: a.usda: {why}\n"
    pooled = _stderr(tmp_path, "--jobs", "1", "a.usda", "b.usda", env=env)  # a worker's
    assert pooled.splitlines() == [
        f"usdrender-lint: error: a.usda: {why}",
        f"usdrender-lint: error: b.usda: {why}",
    ]
    two = _stderr(tmp_path, "--jobs", "2", "a.usda", "b.usda", env=env)
    assert sorted(two.splitlines()) == pooled.splitlines()
    text = _stderr(tmp_path, "-", "--stdin-filename", "a.usda", env=env, stdin=SHOT)
    assert text == lone


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs")
def test_a_time_out_in_usd_s_read_of_the_stage_says_so(tmp_path: Path) -> None:
    hangs = hanging_stage(tmp_path)
    env = {**os.environ, "USDRENDER_LINT_NO_CACHE": "1"}
    (tmp_path / "b.usda").write_text(SHOT)
    why = "timed out after 2 s while USD opened the stage (raise --timeout, or 0 for no limit)"
    assert _stderr(tmp_path, hangs.name, env=env) == f"usdrender-lint: error: {hangs.name}: {why}\n"
    pooled = _stderr(tmp_path, "--jobs", "1", hangs.name, "b.usda", env=env)
    assert pooled == f"usdrender-lint: error: {hangs.name}: {why}\n"


def _dump(*frames: tuple[str, int, str]) -> str:
    lines = ["Current thread 0x00007f0000000000 (most recent call first):"]
    lines += [f'  File "{file}", line {line} in {name}' for file, line, name in frames]
    return "\n".join(lines) + "\n"


def _frame(function: object) -> tuple[str, int, str]:
    code = function.__code__  # type: ignore[attr-defined]
    return code.co_filename, code.co_firstlineno + 1, code.co_name


def test_the_stack_names_a_built_in_rule_by_its_hook() -> None:
    from usdrender_lint.rules.camera.ca005_camera_optics_invalid import CameraOpticsInvalid

    hook = _frame(CameraOpticsInvalid.check_stage)
    dump = _dump(("/usd/helper.py", 3, "read"), hook, _frame(linter.Linter._run))
    assert stalls.site(dump) == "in rule CA005 (camera-optics-invalid)"
    assert "in rule CA005 (camera-optics-invalid) (raise" in timed_out(120, dump)


def test_the_stack_names_a_hook_no_rule_class_here_owns_by_its_place() -> None:
    dump = _dump(("/elsewhere/rule.py", 12, "check_prim"), _frame(linter.Linter._run))
    assert stalls.site(dump) == "in a rule's check_prim (/elsewhere/rule.py:12)"


def test_the_stack_names_the_engine_s_step_or_nothing() -> None:
    assert stalls.site(_dump(_frame(stage.open_stage))) == "while USD opened the stage"
    assert stalls.site(_dump(("/x/y.py", 1, "f"))) is None
    assert stalls.site("") is None
    assert timed_out(2, "") == "timed out after 2 s (raise --timeout, or 0 for no limit)"
