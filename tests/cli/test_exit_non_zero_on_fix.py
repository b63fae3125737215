"""check --fix --exit-non-zero-on-fix: a run that changed a file fails, as ruff's."""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner

from usdrender_lint.cli import cli

# SE007 (a warning with a safe fix): --fix leaves nothing at or above "error".
ONLY_FIXABLE = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform int2 resolution = (1920, 1080)
        uniform bool instantaneousShutter = true
    }
}
"""


def run(*args: str):
    return CliRunner().invoke(cli, ["check", "--isolated", "--no-cache", *args])


def test_a_fix_applied_makes_the_run_fail(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(ONLY_FIXABLE)
    result = run("--fix", "--exit-non-zero-on-fix", str(shot))
    assert result.exit_code == 1, result.output
    assert "instantaneousShutter" not in shot.read_text()
    # Fixed already: nothing to apply, so it passes.
    assert run("--fix", "--exit-non-zero-on-fix", str(shot)).exit_code == 0


def test_without_the_flag_a_fixed_file_passes(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(ONLY_FIXABLE)
    assert run("--fix", str(shot)).exit_code == 0


def test_a_file_that_cannot_be_linted_still_exits_2(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(ONLY_FIXABLE)
    result = run("--fix", "--exit-non-zero-on-fix", str(shot), str(tmp_path / "missing.usda"))
    assert result.exit_code == 2
