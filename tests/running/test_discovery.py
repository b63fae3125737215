"""Walking a folder lints the project's USD files, as ruff walks a project:
hidden files and folders are skipped (``check .`` in a clone linted the 36
schema files of usd-core inside ``.venv/``), so are what ``exclude`` and
``extend-exclude`` name and what ``.gitignore`` files ignore; a path given on
the command line is always linted."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.config import Settings
from usdrender_lint.running.discovery import EVERYTHING, Exclusions, collect_files

LAYER = "#usda 1.0\n"


def tree(root: Path, *names: str) -> None:
    for name in names:
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(LAYER if name.endswith(".usda") else "")


def found(root: Path, exclusions: Exclusions, *paths: str) -> list[str]:
    given = [str(root / p) for p in paths] or [str(root)]
    return sorted(os.path.relpath(f, root) for f in collect_files(given, exclusions=exclusions))


def default(root: Path, **changes) -> Exclusions:
    settings = Settings(source=str(root / ".usdrender-lint.toml"), **changes)
    return Exclusions.of(settings)


def test_hidden_files_and_folders_are_skipped_unless_named(tmp_path: Path) -> None:
    tree(tmp_path, "a.usda", ".venv/lib/schema.usda", ".git/x.usda", "shots/.a.usda.tmp1.usda")
    assert found(tmp_path, default(tmp_path)) == ["a.usda"]
    named = found(tmp_path, default(tmp_path), ".venv/lib/schema.usda", "shots/.a.usda.tmp1.usda")
    assert named == [".venv/lib/schema.usda", "shots/.a.usda.tmp1.usda"]
    assert found(tmp_path, default(tmp_path), ".venv") == [".venv/lib/schema.usda"]
    assert len(found(tmp_path, EVERYTHING)) == 4  # the Python API's collect_files default


def test_a_file_named_relatively_and_absolutely_is_linted_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # It was linted twice, the text report printing each of its findings twice.
    tree(tmp_path, "shots/a.usda")
    (tmp_path / "link").symlink_to("shots")
    monkeypatch.chdir(tmp_path)
    given = ["shots/a.usda", str(tmp_path / "shots" / "a.usda"), "./shots/a.usda", "shots"]
    assert collect_files(given) == ["shots/a.usda"]
    # A link is linted as named (symbolic links are not followed).
    assert collect_files(["shots/a.usda", "link/a.usda"]) == ["shots/a.usda", "link/a.usda"]


def test_the_default_exclude_and_replacing_or_extending_it(tmp_path: Path) -> None:
    tree(tmp_path, "a.usda", "venv/lib/v.usda", "node_modules/n.usda", "wip/w.usda", "b/wip.usda")
    assert found(tmp_path, default(tmp_path)) == ["a.usda", "b/wip.usda", "wip/w.usda"]
    extended = default(tmp_path, extend_exclude=("wip/",))
    assert found(tmp_path, extended) == ["a.usda", "b/wip.usda"]
    replaced = default(tmp_path, exclude=("wip",))
    assert found(tmp_path, replaced) == [
        "a.usda",
        "b/wip.usda",
        "node_modules/n.usda",
        "venv/lib/v.usda",
    ]
    anchored = default(tmp_path, exclude=("/b/*.usda",))  # relative to the config's folder
    assert "b/wip.usda" not in found(tmp_path, anchored)
    assert found(tmp_path, anchored, "b/wip.usda") == ["b/wip.usda"]  # named: linted


def test_exclude_patterns_take_alternatives_in_braces(tmp_path: Path) -> None:
    # per-path-ignores read {a,b} and exclude did not: "{legacy,old}/" skipped nothing.
    tree(tmp_path, "a.usda", "legacy/l.usda", "old/o.usda", "shots/s_wip.usda", "shots/s.usda")
    extended = default(tmp_path, extend_exclude=("{legacy,old}/", "*_{wip,tmp}.usda"))
    assert found(tmp_path, extended) == ["a.usda", "shots/s.usda"]
    replaced = default(tmp_path, exclude=("/{legacy,shots/*_wip.usda}",))
    assert found(tmp_path, replaced) == ["a.usda", "old/o.usda", "shots/s.usda"]
    forced = default(tmp_path, extend_exclude=("{legacy,old}/",), force_exclude=True)
    assert found(tmp_path, forced, "old/o.usda", "a.usda") == ["a.usda"]
    literal = default(tmp_path, extend_exclude=("{legacy}",))  # no comma: no alternatives
    assert "legacy/l.usda" in found(tmp_path, literal)


def test_a_flags_pattern_keeps_the_commas_of_its_braces(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The flags split at commas: '{legacy,old}/' became '{legacy' and 'old}/',
    # which skipped nothing.
    tree(tmp_path, "a.usda", "legacy/l.usda", "old/o.usda", "wip/w.usda")
    monkeypatch.chdir(tmp_path)
    args = ["check", "--isolated", "--show-files", "--extend-exclude", "{legacy,old}/,wip", "."]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 0, result.output
    assert result.stdout.split() == ["a.usda"]


def test_gitignore_files_of_the_repository_are_respected(tmp_path: Path) -> None:
    tree(
        tmp_path,
        ".git/HEAD",
        "shots/a.usda",
        "shots/wip/w.usda",
        "build/out.usda",
        "cache/keep.usda",
        "cache/drop.usda",
        "local.usda",
    )
    (tmp_path / ".gitignore").write_text("build/\nshots/wip/\n")
    (tmp_path / "cache" / ".gitignore").write_text("*.usda\n!keep.usda\n")
    (tmp_path / ".git" / "info").mkdir()
    (tmp_path / ".git" / "info" / "exclude").write_text("local.usda\n")
    assert found(tmp_path, default(tmp_path)) == ["cache/keep.usda", "shots/a.usda"]
    # A folder below the root: the root's .gitignore still applies.
    assert found(tmp_path, default(tmp_path), "shots") == ["shots/a.usda"]
    # Named, an ignored file is linted.
    assert found(tmp_path, default(tmp_path), "build/out.usda") == ["build/out.usda"]
    everything = default(tmp_path, respect_gitignore=False)
    assert len(found(tmp_path, everything)) == 6


def test_a_gitignore_line_git_cannot_read_matches_nothing(tmp_path: Path) -> None:
    # git skips a lone '!' or a line ending in a backslash and reads the rest;
    # the walk stopped with an internal error (pathspec's GitIgnorePatternError).
    tree(tmp_path, ".git/HEAD", "a.usda", "shots/s.usda", "tmp/t.usda")
    (tmp_path / ".gitignore").write_text("!\nshots\\\ntmp/\n")
    assert found(tmp_path, default(tmp_path)) == ["a.usda", "shots/s.usda"]


def test_a_gitignore_outside_a_repository_applies_to_its_folder(tmp_path: Path) -> None:
    tree(tmp_path, "project/a.usda", "project/out/b.usda")
    (tmp_path / "project" / ".gitignore").write_text("out/\n")
    (tmp_path / ".gitignore").write_text("*.usda\n")  # above the walk, no repository: unread
    assert found(tmp_path, default(tmp_path), "project") == ["project/a.usda"]


def test_check_of_a_clone_lints_only_its_files(tmp_path: Path, monkeypatch) -> None:
    tree(tmp_path, ".git/HEAD", ".venv/lib/usd/schema.usda", "build/x.usda")
    (tmp_path / ".gitignore").write_text("build/\n")
    (tmp_path / "shot.usda").write_text(LAYER)
    (tmp_path / "pyproject.toml").write_text('[tool.usdrender-lint]\nextend-exclude = ["old"]\n')
    tree(tmp_path, "old/o.usda")
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(cli, ["check", "--no-cache", "--format", "json", "."])
    assert result.exit_code == 0, result.output
    assert [f["file"] for f in json.loads(result.stdout)["files"]] == ["shot.usda"]
    flag = CliRunner().invoke(
        cli, ["check", "--isolated", "--no-cache", "--format", "json", "--exclude", "shot*", "."]
    )
    assert sorted(f["file"] for f in json.loads(flag.stdout)["files"]) == ["old/o.usda"]


@pytest.mark.parametrize("key", ["exclude", "extend-exclude"])
def test_a_bad_pattern_list_is_a_config_error(tmp_path: Path, key: str) -> None:
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text(f"{key} = 3\n")
    result = CliRunner().invoke(cli, ["check", "--config", str(config), str(tmp_path)])
    assert result.exit_code == 2
    assert f"'{key}' must be a list of strings" in result.output


@pytest.mark.parametrize("key", ["exclude", "extend-exclude"])
@pytest.mark.parametrize("pattern", ["!", "shots\\\\"])  # TOML: a lone '!', a trailing backslash
def test_a_pattern_git_cannot_read_is_a_config_error(
    tmp_path: Path, key: str, pattern: str
) -> None:
    # It was an internal error (pathspec's GitIgnorePatternError) in the walk.
    tree(tmp_path, "a.usda")
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text(f'{key} = ["{pattern}"]\n')
    result = CliRunner().invoke(cli, ["check", "--config", str(config), str(tmp_path)])
    assert result.exit_code == 2
    assert (
        f"{config}:1: '{key}':" in result.output
        and "not a gitignore-style pattern" in result.output
    )
    flag = CliRunner().invoke(cli, ["check", "--isolated", f"--{key}", "!", str(tmp_path)])
    assert flag.exit_code == 2 and "internal error" not in flag.output
    assert f"--{key}: '!' is not a gitignore-style pattern" in flag.output


# Bare names (the default exclude, git's own comment-only info/exclude) are
# matched without importing pathspec; the answers must be pathspec's.
_LINE_SETS = [
    ["node_modules", "site-packages", "venv", "__pypackages__"],
    ["# only comments", "", "#venv"],
    ["build", "out.usda", "a.b.c", "-dash_"],
]
_PATHS = [
    "venv", "venv/", "a/venv", "a/venv/", "a/venv/b.usda", "venvs/x.usda", "a/myvenv/x.usda",
    "node_modules/p/x.usda", "x/site-packages/", "build", "build/", "a/build/b/c.usda",
    "out.usda", "a/out.usda", "out.usda.bak", "a.b.c/x", "abbc/x", "-dash_/y.usda", "#venv/x",
    "Venv/x.usda", "shot.usda",
]  # fmt: skip


@pytest.mark.parametrize("lines", _LINE_SETS)
def test_bare_names_match_as_pathspec_matches_them(lines: list[str]) -> None:
    from pathspec import GitIgnoreSpec

    from usdrender_lint.running import discovery

    ours = discovery._spec(lines)
    assert isinstance(ours, discovery._Names)
    theirs = GitIgnoreSpec.from_lines(lines)
    for path in _PATHS:
        assert ours.match_file(path) == theirs.match_file(path), path
        assert ours.check_file(path).include == theirs.check_file(path).include, path


@pytest.mark.parametrize(
    "line", ["*.usda", "build/", "/build", "!keep", "a\\ b", "venv ", " venv", "[ab]", "..", "."]
)
def test_any_other_line_is_pathspec_s(line: str) -> None:
    from pathspec import GitIgnoreSpec

    from usdrender_lint.running import discovery

    assert isinstance(discovery._spec(["venv", line]), GitIgnoreSpec)


def test_a_walk_with_the_default_exclude_does_not_import_pathspec(tmp_path: Path) -> None:
    import subprocess
    import sys

    tree(tmp_path, "a/shot.usda", "venv/lib.usda", "b/site-packages/c.usda")
    code = (
        "import sys\n"
        "from usdrender_lint.config import Settings\n"
        "from usdrender_lint.running.discovery import Exclusions, collect_files\n"
        f"settings = Settings(source={str(tmp_path / '.usdrender-lint.toml')!r})\n"
        f"print(len(collect_files([{str(tmp_path)!r}], exclusions=Exclusions.of(settings))))\n"
        "print('pathspec' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["1", "False"]
