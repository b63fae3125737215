"""check -q/--quiet (the findings and nothing else) and -s/--silent (the exit
code, and the files that could not be linted), as ruff's."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.running import pipeline

REPO = Path(__file__).parents[2]
BROKEN = REPO / "examples" / "broken_shot" / "shot.usda"
SUMMARY = "findings in"

# SE007: deprecated instantaneousShutter (a safe fix); SE001: zero resolution (none).
FIXABLE = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform int2 resolution = (0, 1080)
        uniform bool instantaneousShutter = true
    }
}
"""


def run(*args: str):
    return CliRunner().invoke(cli, ["check", "--isolated", "--no-cache", *args])


@pytest.mark.parametrize("flag", ["-q", "--quiet"])
def test_quiet_prints_the_findings_and_no_summary(flag: str) -> None:
    loud = run(str(BROKEN))
    quiet = run(flag, str(BROKEN))
    assert loud.exit_code == quiet.exit_code == 1
    assert SUMMARY in loud.stdout and SUMMARY not in quiet.stdout
    assert quiet.stdout.splitlines() == loud.stdout.splitlines()[:-1]


def test_quiet_keeps_the_statistics_asked_for() -> None:
    loud = run("--statistics", str(BROKEN)).stdout.splitlines()
    quiet = run("--quiet", "--statistics", str(BROKEN)).stdout.splitlines()
    at = next(i for i, line in enumerate(loud) if SUMMARY in line)
    assert quiet == loud[:at] + loud[at + 1 :]
    assert any("instantaneous-shutter-deprecated" in line for line in quiet)


def test_quiet_fix_prints_what_remains_not_what_was_fixed(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(FIXABLE)
    result = run("--quiet", "--fix", str(shot))
    assert result.exit_code == 1, result.output
    assert "SE001" in result.stdout
    assert "SE007" not in result.stdout  # fixed, and not said
    assert SUMMARY not in result.stdout
    assert "instantaneousShutter" not in shot.read_text()


def test_quiet_drops_the_notes_on_stderr(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(FIXABLE)
    baseline = tmp_path / "baseline.json"
    assert run("--write-baseline", str(baseline), str(shot)).exit_code == 0
    shot.write_text(FIXABLE.replace("(0, 1080)", "(1920, 1080)"))
    loud = run("--baseline", str(baseline), str(shot))
    assert "no longer occur" in loud.stderr
    quiet = run("--quiet", "--baseline", str(baseline), str(shot))
    assert quiet.stderr == ""


@pytest.mark.parametrize("flag", ["-s", "--silent"])
def test_silent_prints_nothing_and_exits_by_the_findings(flag: str, tmp_path: Path) -> None:
    result = run(flag, str(BROKEN))
    assert result.exit_code == 1
    assert result.stdout == ""
    clean = tmp_path / "clean.usda"
    clean.write_text(FIXABLE.replace("(0, 1080)", "(1920, 1080)").replace("true", "false"))
    assert run(flag, "--select", "SE001", str(clean)).exit_code == 0


def test_silent_still_writes_the_report_output_names(tmp_path: Path) -> None:
    report = tmp_path / "report.json"
    result = run("--silent", "--format", "json", "--output", str(report), str(BROKEN))
    assert result.exit_code == 1
    assert result.stdout == ""
    assert json.loads(report.read_text())["files"]


def test_silent_still_says_a_file_that_could_not_be_linted(tmp_path: Path) -> None:
    missing = tmp_path / "missing.usda"
    result = run("--silent", str(missing))
    assert result.exit_code == 2
    assert result.stdout == ""
    assert "missing.usda" in result.stderr and len(result.stderr.splitlines()) == 1


@pytest.mark.parametrize("flag", ["--quiet", "--silent"])
def test_no_progress_bar_when_quiet(flag: str, monkeypatch: pytest.MonkeyPatch) -> None:
    asked: list[bool | None] = []
    real_run = pipeline.run

    def spy(request: pipeline.Request) -> pipeline.Outcome:
        asked.append(request.progress)
        return real_run(request)

    monkeypatch.setattr(pipeline, "run", spy)
    run(flag, str(BROKEN))
    run(str(BROKEN))
    assert asked == [False, None]


def test_silent_diff_still_prints_the_diff(tmp_path: Path) -> None:
    """--diff asks for the diff: it is the command's data, not its chatter."""
    shot = tmp_path / "shot.usda"
    shot.write_text(FIXABLE)
    copy = tmp_path / "copy.usda"
    shutil.copy(shot, copy)
    result = run("--silent", "--diff", str(shot))
    assert "instantaneousShutter" in result.stdout
    assert shot.read_text() == copy.read_text()
