"""--diff prints a patch that ``git apply`` and ``patch -p1`` accept from the
current directory, and exits 1 when a fix is pending, 0 when none, 2 on errors."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.fixing.diff import NO_NEWLINE, patch, patch_name

SHOT = """#usda 1.0

def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform token aspectRatioConformPolicy = "cropaperture"
    }
}"""  # no line end at the end of the file


def diff(*args: str):
    base = ["check", "--isolated", "-j", "1", "--timeout", "0", "--select", "SE006", "--diff"]
    return CliRunner().invoke(cli, [*base, *args])


@pytest.fixture
def shots(tmp_path: Path, monkeypatch) -> Path:
    (tmp_path / "shots").mkdir()
    (tmp_path / "shots" / "a.usda").write_text(SHOT, encoding="utf-8")
    (tmp_path / "shots" / "b.usda").write_text(SHOT + "\n", encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize(
    "tool",
    [["git", "apply", "--check"], ["patch", "-p1", "--dry-run", "-i"]],
    ids=["git apply", "patch -p1"],
)
def test_the_patch_applies_from_the_current_directory(shots: Path, tool: list[str]) -> None:
    if shutil.which(tool[0]) is None:
        pytest.skip(f"{tool[0]} is not installed")
    result = diff("shots")
    assert result.exit_code == 1  # fixes are pending
    assert "--- a/shots/a.usda\n+++ b/shots/a.usda\n" in result.stdout
    assert NO_NEWLINE in result.stdout
    (shots / "fixes.patch").write_text(result.stdout, encoding="utf-8")
    applied = subprocess.run([*tool, "fixes.patch"], cwd=shots, capture_output=True, text=True)
    assert applied.returncode == 0, applied.stdout + applied.stderr
    # And really applied, it gives what --fix writes.
    subprocess.run(["patch", "-p1", "-s", "-i", "fixes.patch"], cwd=shots, check=True)
    patched = (shots / "shots" / "a.usda").read_text(encoding="utf-8")
    assert patched == SHOT.replace('"cropaperture"', '"cropAperture"')


def test_a_file_outside_the_current_directory_is_a_note(tmp_path: Path, monkeypatch) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(SHOT, encoding="utf-8")
    (tmp_path / "here").mkdir()
    monkeypatch.chdir(tmp_path / "here")
    result = diff(str(shot))
    assert result.stdout == ""
    assert "is outside the current directory, so it is not in the patch" in result.stderr
    assert result.exit_code == 1


def test_nothing_pending_exits_0_even_with_findings(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(SHOT.replace('"cropaperture"', '"nonsense"'), encoding="utf-8")
    result = diff(str(shot))  # SE006 has no fix for a token nothing resembles
    assert result.exit_code == 0 and result.stdout == ""


def test_an_error_exits_2(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(SHOT, encoding="utf-8")
    assert diff(str(shot), str(tmp_path / "missing.usda")).exit_code == 2


def test_patch_marks_a_missing_final_line_end_and_splits_only_at_line_ends() -> None:
    text = patch("x.usda", 'a\nstring s = "\x0c"\nb', 'a\nstring s = "\x0c"\nc', cwd=".")
    assert text is not None
    assert text.endswith("-b\n" + NO_NEWLINE + "+c\n" + NO_NEWLINE)
    assert '\x0c"\n' in text  # a form feed is not a line end for patch tools


def test_patch_names_are_relative_and_never_leave_the_directory(tmp_path: Path) -> None:
    (tmp_path / "in").mkdir()
    assert patch_name(str(tmp_path / "in" / "x.usda"), str(tmp_path)) == "in/x.usda"
    assert patch_name(str(tmp_path / "x.usda"), str(tmp_path / "in")) is None


@pytest.mark.parametrize(
    "tool",
    [["git", "apply"], ["patch", "-p1", "-s", "-i"]],
    ids=["git apply", "patch -p1"],
)
def test_names_with_controls_and_quotes_survive_the_patch(
    tmp_path: Path, monkeypatch, tool: list[str]
) -> None:
    """A name holding a line break broke the header in two (neither tool read
    the patch) and one holding an escape code sent it to the terminal: such
    names are quoted as git quotes them."""
    if shutil.which(tool[0]) is None:
        pytest.skip(f"{tool[0]} is not installed")
    names = ["x\ny.usda", "e\x1b[31m.usda", 'q"\\.usda']
    try:
        for name in names:
            (tmp_path / name).write_text(SHOT, encoding="utf-8")
    except OSError:
        pytest.skip("this file system refuses such names")
    monkeypatch.chdir(tmp_path)
    result = diff(".")
    assert result.exit_code == 1
    assert "\x1b" not in result.stdout
    assert '--- "a/x\\ny.usda"\n+++ "b/x\\ny.usda"\n' in result.stdout
    assert '--- "a/e\\033[31m.usda"\n' in result.stdout
    assert '--- "a/q\\"\\\\.usda"\n' in result.stdout
    (tmp_path / "fixes.patch").write_text(result.stdout, encoding="utf-8")
    if tool[0] == "git":
        subprocess.run(["git", "init", "-q", "."], cwd=tmp_path, check=True)
    applied = subprocess.run([*tool, "fixes.patch"], cwd=tmp_path, capture_output=True, text=True)
    assert applied.returncode == 0, applied.stdout + applied.stderr
    for name in names:
        patched = (tmp_path / name).read_text(encoding="utf-8")
        assert patched == SHOT.replace('"cropaperture"', '"cropAperture"'), name
