"""--diff prints a patch that ``git apply -p0`` and ``patch -p0`` accept from the
current directory (ruff's form: both headers name the file as given), and
exits 1 when a fix is pending, 0 when none, 2 on errors."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.fixing.diff import NO_NEWLINE, merged, patch, patch_name

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
    [["git", "apply", "-p0", "--check"], ["patch", "-p0", "--dry-run", "-i"]],
    ids=["git apply -p0", "patch -p0"],
)
def test_the_patch_applies_from_the_current_directory(shots: Path, tool: list[str]) -> None:
    if shutil.which(tool[0]) is None:
        pytest.skip(f"{tool[0]} is not installed")
    result = diff("shots")
    assert result.exit_code == 1  # fixes are pending
    assert "--- shots/a.usda\n+++ shots/a.usda\n" in result.stdout
    assert NO_NEWLINE in result.stdout
    (shots / "fixes.patch").write_text(result.stdout, encoding="utf-8")
    applied = subprocess.run([*tool, "fixes.patch"], cwd=shots, capture_output=True, text=True)
    assert applied.returncode == 0, applied.stdout + applied.stderr
    # And really applied, it gives what --fix writes.
    subprocess.run(["patch", "-p0", "-s", "-i", "fixes.patch"], cwd=shots, check=True)
    patched = (shots / "shots" / "a.usda").read_text(encoding="utf-8")
    assert patched == SHOT.replace('"cropaperture"', '"cropAperture"')


@pytest.mark.parametrize("spelling", ["relative", "absolute"])
def test_a_file_outside_the_current_directory_is_named_as_given(
    tmp_path: Path, monkeypatch, spelling: str
) -> None:
    """ruff's and diff's users expect the patch, the file named as given: GNU
    patch applies it named (``patch -p0 FILE``), git with ``--unsafe-paths``."""
    shot = tmp_path / "shot.usda"
    shot.write_text(SHOT, encoding="utf-8")
    here = tmp_path / "here"
    here.mkdir()
    monkeypatch.chdir(here)
    given = "../shot.usda" if spelling == "relative" else str(shot)
    result = diff(given)
    assert result.exit_code == 1
    assert result.stdout.startswith(f"--- {given}\n+++ {given}\n")
    assert "not in the patch" not in result.stderr
    (here / "fixes.patch").write_text(result.stdout, encoding="utf-8")
    tools = [["patch", "-p0", "--dry-run", given, "-i", "fixes.patch"]]
    tools.append(["git", "apply", "-p0", "--unsafe-paths", "--check", "fixes.patch"])
    for tool in tools:
        if shutil.which(tool[0]) is None:
            continue
        applied = subprocess.run(tool, cwd=here, capture_output=True, text=True)
        assert applied.returncode == 0, applied.stdout + applied.stderr
    subprocess.run(["patch", "-p0", "-s", given, "-i", "fixes.patch"], cwd=here, check=True)
    assert shot.read_text(encoding="utf-8") == SHOT.replace('"cropaperture"', '"cropAperture"')


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


def test_patch_names_are_relative_below_the_directory_else_as_given(tmp_path: Path) -> None:
    (tmp_path / "in").mkdir()
    inside, outside = str(tmp_path / "in" / "x.usda"), str(tmp_path / "x.usda")
    assert patch_name(inside, str(tmp_path)) == "in/x.usda"
    assert patch_name(outside, str(tmp_path / "in"), "../x.usda") == "../x.usda"
    assert patch_name(outside, str(tmp_path / "in"), "./../x.usda") == "../x.usda"
    # A layer the command line did not name (a sublayer) is named absolutely.
    assert patch_name(outside, str(tmp_path / "in"), "../other.usda") == outside


@pytest.mark.parametrize(
    "tool",
    [["git", "apply", "-p0"], ["patch", "-p0", "-s", "-i"]],
    ids=["git apply -p0", "patch -p0"],
)
def test_names_with_controls_and_quotes_survive_the_patch(
    tmp_path: Path, monkeypatch, tool: list[str]
) -> None:
    """A name holding a line break broke the header in two (neither tool read
    the patch) and one holding an escape code sent it to the terminal: such
    names are quoted as git quotes them."""
    if shutil.which(tool[0]) is None:
        pytest.skip(f"{tool[0]} is not installed")
    names = ["x\ny.usda", "e\x1b[31m.usda", 'q"\\.usda', "my shot é.usda"]
    try:
        for name in names:
            (tmp_path / name).write_text(SHOT, encoding="utf-8")
    except OSError:
        pytest.skip("this file system refuses such names")
    monkeypatch.chdir(tmp_path)
    result = diff(".")
    assert result.exit_code == 1
    assert "\x1b" not in result.stdout
    assert '--- "x\\ny.usda"\n+++ "x\\ny.usda"\n' in result.stdout
    assert '--- "e\\033[31m.usda"\n' in result.stdout
    assert '--- "q\\"\\\\.usda"\n' in result.stdout
    # GNU patch ends an unquoted name at a space.
    assert '--- "my shot \\303\\251.usda"\n' in result.stdout
    (tmp_path / "fixes.patch").write_text(result.stdout, encoding="utf-8")
    if tool[0] == "git":
        subprocess.run(["git", "init", "-q", "."], cwd=tmp_path, check=True)
    applied = subprocess.run([*tool, "fixes.patch"], cwd=tmp_path, capture_output=True, text=True)
    assert applied.returncode == 0, applied.stdout + applied.stderr
    for name in names:
        patched = (tmp_path / name).read_text(encoding="utf-8")
        assert patched == SHOT.replace('"cropaperture"', '"cropAperture"'), name


@pytest.mark.parametrize("timeout", ["0", "120"], ids=["in-process", "in-workers"])
def test_two_stages_sharing_a_layer_show_its_fix_once(
    tmp_path: Path, monkeypatch, timeout: str
) -> None:
    """--diff previews --fix: --fix writes the shared layer after the first
    stage and the second finds nothing left, so the patch holds it once."""
    (tmp_path / "seq").mkdir()
    (tmp_path / "seq" / "lighting.usda").write_text(SHOT + "\n", encoding="utf-8")
    for shot in ("010", "020"):
        (tmp_path / shot).mkdir()
        (tmp_path / shot / "shot.usda").write_text(
            "#usda 1.0\n(\n    subLayers = [@../seq/lighting.usda@]\n)\n", encoding="utf-8"
        )
    monkeypatch.chdir(tmp_path)
    result = diff("--timeout", timeout, "010/shot.usda", "020/shot.usda")
    assert result.exit_code == 1
    assert result.stdout.count("--- seq/lighting.usda\n") == 1
    assert "1 fix would be applied" in result.stderr
    (tmp_path / "fixes.patch").write_text(result.stdout, encoding="utf-8")
    if shutil.which("patch") is not None:
        subprocess.run(["patch", "-p0", "-s", "-i", "fixes.patch"], cwd=tmp_path, check=True)
        fixed = (tmp_path / "seq" / "lighting.usda").read_text(encoding="utf-8")
        assert fixed == SHOT.replace('"cropaperture"', '"cropAperture"') + "\n"


def test_merged_holds_every_stage_s_edit_once_or_says_it_cannot() -> None:
    base = "a\nb\nc\n"
    assert merged(base, ["a\nB\nc\n", "a\nB\nc\nd\n", "z\na\nb\nc\n"]) == "z\na\nB\nc\nd\n"
    assert merged(base, ["a\nb\nc\n"]) == base
    assert merged(base, ["a\nX\nc\n", "a\nY\nc\n"]) is None  # the same line, two ways
