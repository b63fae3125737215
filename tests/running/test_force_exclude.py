"""``force-exclude`` (``--force-exclude``, as ruff's): a path given is skipped
where a walk from the configuration's folder would skip it. A pre-commit hook
names every staged file, so without it ``extend-exclude = ["reference/"]`` kept
nothing out of a commit's lint."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.config import Settings
from usdrender_lint.running.discovery import Exclusions, collect_files, force_excluded

REPO = Path(__file__).resolve().parents[2]
BROKEN = (REPO / "examples" / "broken_shot" / "shot.usda").read_text(encoding="utf-8")

#: Every way a walk skips a file: hidden names, exclude patterns (bare, anchored,
#: globbed), .gitignore files at the root and deeper (with a re-include), and
#: git's info/exclude; and files a walk keeps beside each.
TREE = (
    "shots/a.usda",
    "shots/.a.usda.tmp.usda",
    ".hidden/h.usda",
    "reference/r.usda",
    "shots/reference/deep.usda",
    "old/o_backup.usda",
    "old/o.usda",
    "build/b.usda",
    "cache/keep.usda",
    "cache/drop.usda",
    "local.usda",
    "venv/lib/v.usda",
)


def _tree(root: Path) -> None:
    for name in TREE:
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("#usda 1.0\n")
    (root / ".git" / "info").mkdir(parents=True)
    (root / ".git" / "info" / "exclude").write_text("local.usda\n")
    (root / ".gitignore").write_text("build/\n")
    (root / "cache" / ".gitignore").write_text("*.usda\n!keep.usda\n")


def _exclusions(root: Path, force: bool = True) -> Exclusions:
    settings = Settings(
        source=str(root / ".usdrender-lint.toml"),
        extend_exclude=("reference/", "/old/*_backup.usda"),
        force_exclude=force,
    )
    return Exclusions.of(settings)


def _relative(root: Path, files: list[str]) -> list[str]:
    return sorted(os.path.relpath(f, root) for f in files)


def test_every_file_named_gives_what_the_walk_gives(tmp_path: Path) -> None:
    _tree(tmp_path)
    walked = _relative(tmp_path, collect_files([str(tmp_path)], exclusions=_exclusions(tmp_path)))
    assert walked == ["cache/keep.usda", "old/o.usda", "shots/a.usda"]
    every = [str(tmp_path / name) for name in TREE]
    named = _relative(tmp_path, collect_files(every, exclusions=_exclusions(tmp_path)))
    assert named == walked
    # Relative names from the configuration's folder, as pre-commit passes them.
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        assert sorted(collect_files(list(TREE), exclusions=_exclusions(tmp_path))) == walked
    finally:
        os.chdir(cwd)
    # Without it, every path given is linted.
    assert len(collect_files(every, exclusions=_exclusions(tmp_path, force=False))) == len(TREE)


def test_a_folder_given_is_skipped_or_walked_as_the_walk_would(tmp_path: Path) -> None:
    _tree(tmp_path)
    exclusions = _exclusions(tmp_path)
    assert collect_files([str(tmp_path / "reference")], exclusions=exclusions) == []
    assert collect_files([str(tmp_path / ".hidden")], exclusions=exclusions) == []
    assert _relative(tmp_path, collect_files([str(tmp_path / "cache")], exclusions=exclusions)) == [
        "cache/keep.usda"
    ]


def test_paths_outside_the_configuration_folder_are_not_judged_by_it(tmp_path: Path) -> None:
    project = tmp_path / "project"
    _tree(project)
    (tmp_path / ".outside").mkdir()
    outside = tmp_path / ".outside" / "reference.usda"
    outside.write_text("#usda 1.0\n")
    exclusions = _exclusions(project)
    assert not force_excluded(str(outside), exclusions)
    # The configuration's own folder, given, is walked (its name is never judged).
    hidden_project = tmp_path / ".project"
    _tree(hidden_project)
    assert collect_files([str(hidden_project)], exclusions=_exclusions(hidden_project))
    assert force_excluded(str(project / "reference" / "r.usda"), exclusions)
    assert not force_excluded(str(project / "reference" / "r.usda"), _exclusions(project, False))


def _check(root: Path, *args: str, stdin: str | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--no-cache", *args],
        cwd=root,
        input=stdin,
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.fixture
def project(tmp_path: Path) -> Path:
    for name in ("shots/shot.usda", "reference/shot.usda"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(BROKEN, encoding="utf-8")
    (tmp_path / "pyproject.toml").write_text(
        '[tool.usdrender-lint]\nextend-exclude = ["reference/"]\n', encoding="utf-8"
    )
    return tmp_path


def _files(run: subprocess.CompletedProcess) -> list[str]:
    return [f["file"] for f in json.loads(run.stdout)["files"]]


def test_the_flag_the_config_key_and_its_no_form(project: Path) -> None:
    both = ("--format", "json", "shots/shot.usda", "reference/shot.usda")
    assert _files(_check(project, *both)) == ["shots/shot.usda", "reference/shot.usda"]
    forced = _check(project, "--force-exclude", *both)
    assert forced.returncode == 1, forced.stderr
    assert _files(forced) == ["shots/shot.usda"]
    only_excluded = _check(project, "--force-exclude", "reference/shot.usda")
    assert only_excluded.returncode == 0, only_excluded.stdout + only_excluded.stderr
    assert "0 findings in 0 files" in only_excluded.stdout
    with (project / "pyproject.toml").open("a", encoding="utf-8") as config:
        config.write("force-exclude = true\n")
    assert _files(_check(project, *both)) == ["shots/shot.usda"]
    undone = _check(project, "--no-force-exclude", *both)
    assert _files(undone) == ["shots/shot.usda", "reference/shot.usda"]


def test_a_text_named_as_an_excluded_file_is_neither_linted_nor_fixed(project: Path) -> None:
    named = ("--force-exclude", "--stdin-filename", "reference/shot.usda", "-")
    linted = _check(project, "--format", "json", *named, stdin=BROKEN)
    assert linted.returncode == 0, linted.stderr
    assert _files(linted) == []
    fixed = _check(project, "--fix", "--unsafe-fixes", *named, stdin=BROKEN)
    assert fixed.returncode == 0, fixed.stderr
    assert fixed.stdout == BROKEN  # as it came: an editor's buffer is kept
    diff = _check(project, "--diff", *named, stdin=BROKEN)
    assert (diff.returncode, diff.stdout) == (0, "")
    # The same text named as a file the walk keeps is linted and fixed.
    kept = ("--force-exclude", "--stdin-filename", "shots/shot.usda", "-")
    assert _check(project, *kept, stdin=BROKEN).returncode == 1
    assert _check(project, "--fix", *kept, stdin=BROKEN).stdout != BROKEN


def test_spec_takes_it_too(project: Path) -> None:
    runner = CliRunner()
    cwd = os.getcwd()
    os.chdir(project)
    try:
        given = ["spec", "--format", "json", "shots/shot.usda", "reference/shot.usda"]
        forced = runner.invoke(cli, [*given[:1], "--force-exclude", *given[1:]])
        plain = runner.invoke(cli, given)
    finally:
        os.chdir(cwd)
    assert forced.exit_code == 0 and plain.exit_code == 0, forced.output + plain.output
    assert "reference/shot.usda" in plain.stdout
    assert "reference/shot.usda" not in forced.stdout
    assert "shots/shot.usda" in forced.stdout
