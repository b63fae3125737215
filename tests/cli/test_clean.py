"""``usdrender-lint clean``: it removes the result caches a check of the same
paths uses (the project's, a nested configuration's, any below), only the
cache's own files, and leaves every other folder and file as it was."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest
from cli_support import BROKEN, invoke_in

from usdrender_lint.running.result_cache import CACHE_DIR_NAME, ENTRIES_DIR

pytestmark = pytest.mark.heavy(seconds=12)

ENTRY = "0123456789abcdef0123456789abcdef01234567.json"


@pytest.fixture(autouse=True)
def _cache_on(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("USDRENDER_LINT_NO_CACHE", raising=False)
    monkeypatch.delenv("USDRENDER_LINT_CACHE_DIR", raising=False)


def _project(root: Path, *folders: str) -> None:
    for folder in ("", *folders):
        (root / folder).mkdir(parents=True, exist_ok=True)
        shutil.copy(BROKEN, root / folder / "shot.usda")


def _entries(cache: Path) -> list[str]:
    return sorted(p.name for p in (cache / ENTRIES_DIR).glob("*.json"))


def _checked(root: Path, *args: str) -> None:
    result = invoke_in(root, "check", *args)
    assert result.exit_code == 1, result.output


def test_clean_removes_the_cache_a_check_wrote_and_the_next_check_writes_it_again(
    tmp_path: Path,
) -> None:
    _project(tmp_path, "shots/a")
    _checked(tmp_path, ".")
    cache = tmp_path / CACHE_DIR_NAME
    assert len(_entries(cache)) == 2
    result = invoke_in(tmp_path, "clean")
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith(f"Removed {CACHE_DIR_NAME} (2 entries, ")
    assert not cache.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["shot.usda", "shots"]
    again = invoke_in(tmp_path, "clean")
    assert (again.exit_code, again.stdout) == (0, "No result cache to remove.\n")
    _checked(tmp_path, ".")
    assert len(_entries(cache)) == 2


def test_a_file_of_someone_else_in_the_cache_folder_stays_and_so_does_the_folder(
    tmp_path: Path,
) -> None:
    _project(tmp_path)
    _checked(tmp_path, ".")
    cache = tmp_path / CACHE_DIR_NAME
    (cache / "notes.txt").write_text("mine\n")
    # What the cache leaves behind when a run is killed mid-write, and an older format's entry.
    (cache / ENTRIES_DIR / f".{ENTRY}.abcd_123.tmp").write_bytes(b"{")
    (cache / "v2").mkdir()
    (cache / "v2" / ENTRY).write_text("{}")
    result = invoke_in(tmp_path, "clean")
    assert result.exit_code == 0, result.output
    assert "kept the folder: it holds 1 other file(s): notes.txt" in result.stdout
    assert "(2 entries, " in result.stdout
    assert sorted(p.name for p in cache.iterdir()) == ["CACHEDIR.TAG", "notes.txt"]
    assert (cache / "notes.txt").read_text() == "mine\n"


def test_a_folder_of_the_cache_s_name_that_is_not_one_is_left_alone(tmp_path: Path) -> None:
    _project(tmp_path)
    foreign = tmp_path / "assets" / CACHE_DIR_NAME
    foreign.mkdir(parents=True)
    (foreign / ENTRY).write_text("not ours")
    result = invoke_in(tmp_path, "clean")
    assert result.exit_code == 0, result.output
    assert result.stdout == "No result cache to remove.\n"
    assert result.stderr == (
        f"usdrender-lint: assets/{CACHE_DIR_NAME} is not a usdrender-lint cache folder; "
        "left alone\n"
    )
    assert (foreign / ENTRY).read_text() == "not ours"


def test_cache_dir_naming_a_folder_of_the_user_s_is_refused_in_one_line(tmp_path: Path) -> None:
    assets = tmp_path / "assets"
    assets.mkdir()
    (assets / "chair.usda").write_text("#usda 1.0\n")
    result = invoke_in(tmp_path, "clean", "--cache-dir", "assets")
    assert result.exit_code == 2
    assert result.stderr == (
        "usdrender-lint: error: assets is not a usdrender-lint cache folder "
        "(no CACHEDIR.TAG of ours)\n"
    )
    assert [p.name for p in assets.iterdir()] == ["chair.usda"]
    empty = tmp_path / "empty"
    empty.mkdir()
    result = invoke_in(tmp_path, "clean", "--cache-dir", "empty")
    assert (result.exit_code, result.stdout) == (0, "No result cache to remove.\n")
    assert empty.is_dir()


def test_the_cache_dir_of_the_flag_the_environment_and_configurations(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _project(tmp_path, "shows/a", "shows/b")
    (tmp_path / "shows/a/pyproject.toml").write_text(
        '[tool.usdrender-lint]\ncache-dir = "../../build/a-cache"\n'
    )
    _checked(tmp_path, ".")  # a split run: the root's cache and show a's own
    assert len(_entries(tmp_path / "build/a-cache")) == 1
    assert len(_entries(tmp_path / CACHE_DIR_NAME)) == 2
    # --isolated: one configuration for all, so show a's cache is not one of this check's.
    result = invoke_in(tmp_path, "clean", "--isolated")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "build/a-cache").is_dir()
    assert not (tmp_path / CACHE_DIR_NAME).exists()
    # The nested configuration's, found below the path given.
    result = invoke_in(tmp_path, "clean", "shows")
    assert result.stdout.startswith("Removed build/a-cache (1 entry, "), result.output
    assert not (tmp_path / "build/a-cache").exists()
    # Given a folder inside show a, its configuration's cache is the one its check uses.
    _checked(tmp_path / "shows/a", ".")
    result = invoke_in(tmp_path / "shows/a", "clean", "shot.usda")
    assert result.stdout.startswith("Removed ") and "/build/a-cache (1 entry, " in result.stdout
    assert not (tmp_path / "build/a-cache").exists()
    # --cache-dir and USDRENDER_LINT_CACHE_DIR name the one folder.
    _checked(tmp_path, ".", "--cache-dir", "elsewhere")
    monkeypatch.setenv("USDRENDER_LINT_CACHE_DIR", str(tmp_path / "elsewhere"))
    result = invoke_in(tmp_path, "clean")
    assert result.stdout.startswith("Removed elsewhere (3 entries, "), result.output
    assert not (tmp_path / "elsewhere").exists()


def test_a_linked_cache_folder_is_emptied_and_the_link_and_its_folder_stay(
    tmp_path: Path,
) -> None:
    project, scratch = tmp_path / "project", tmp_path / "scratch"
    _project(project)
    scratch.mkdir()
    (project / CACHE_DIR_NAME).symlink_to(scratch)
    _checked(project, ".")
    assert len(_entries(scratch)) == 1
    # A linked folder is not walked into: its cache is not this project's.
    (project / "linked").symlink_to(tmp_path / "other")
    _project(tmp_path / "other")
    _checked(tmp_path / "other", ".")
    result = invoke_in(project, "clean")
    assert result.exit_code == 0, result.output
    assert (project / CACHE_DIR_NAME).is_symlink() and scratch.is_dir()
    assert list(scratch.iterdir()) == []
    assert len(_entries(tmp_path / "other" / CACHE_DIR_NAME)) == 1


def test_a_missing_path_is_one_error_line_and_the_others_are_cleaned(tmp_path: Path) -> None:
    _project(tmp_path, "a")
    _checked(tmp_path / "a", ".")
    result = invoke_in(tmp_path, "clean", "missing", "a")
    assert result.exit_code == 2
    assert result.stderr == "usdrender-lint: error: missing: no such file or folder\n"
    assert result.stdout.startswith(f"Removed a/{CACHE_DIR_NAME} (1 entry, ")
    assert not (tmp_path / "a" / CACHE_DIR_NAME).exists()


def test_a_broken_nested_configuration_is_a_note_and_the_rest_is_cleaned(tmp_path: Path) -> None:
    _project(tmp_path, "shows/a")
    _checked(tmp_path, ".")
    (tmp_path / "shows/a/.usdrender-lint.toml").write_text("cache-dir = [\n")
    result = invoke_in(tmp_path, "clean")
    assert result.exit_code == 0, result.output
    assert not (tmp_path / CACHE_DIR_NAME).exists()
    (line,) = result.stderr.splitlines()
    assert line.startswith("usdrender-lint: ") and ".usdrender-lint.toml" in line
    assert line.endswith("its cache is not looked for")


def test_clean_writes_nothing_where_there_is_no_cache(tmp_path: Path) -> None:
    _project(tmp_path, "a")
    before = sorted(os.walk(tmp_path))
    result = invoke_in(tmp_path, "clean", "a", "shot.usda")
    assert (result.exit_code, result.stdout, result.stderr) == (
        0,
        "No result cache to remove.\n",
        "",
    )
    assert sorted(os.walk(tmp_path)) == before


def test_a_linked_cache_folder_below_the_paths_is_not_followed(tmp_path: Path) -> None:
    project, shared = tmp_path / "project", tmp_path / "shared-cache"
    _project(project, "sub")
    _checked(project, ".", "--cache-dir", str(shared))
    (project / "sub" / CACHE_DIR_NAME).symlink_to(shared)
    result = invoke_in(project, "clean")
    assert result.exit_code == 0, result.output
    assert result.stdout == "No result cache to remove.\n"
    assert len(_entries(shared)) == 2 and (shared / "CACHEDIR.TAG").is_file()


def test_only_the_cache_s_own_temporary_files_go(tmp_path: Path) -> None:
    _project(tmp_path)
    _checked(tmp_path, ".")
    cache = tmp_path / CACHE_DIR_NAME
    (cache / ".CACHEDIR.TAG.bak").write_text("mine\n")  # a user's, whatever its name
    (cache / ".CACHEDIR.TAG.ab_12xyz.tmp").write_text("interrupted\n")  # the tag's own
    result = invoke_in(tmp_path, "clean")
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in cache.iterdir()) == [".CACHEDIR.TAG.bak", "CACHEDIR.TAG"]


def test_a_cache_file_that_cannot_be_removed_is_an_error_not_a_user_s_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _project(tmp_path)
    _checked(tmp_path, ".")
    cache = tmp_path / CACHE_DIR_NAME
    (entry,) = _entries(cache)
    unlink = Path.unlink

    def refusing(path: Path, missing_ok: bool = False) -> None:
        if path.name == entry:
            raise PermissionError(1, "Operation not permitted")
        unlink(path, missing_ok)

    monkeypatch.setattr(Path, "unlink", refusing)
    result = invoke_in(tmp_path, "clean")
    assert result.exit_code == 2
    assert "other file" not in result.stdout
    assert result.stderr == (
        f"usdrender-lint: error: {CACHE_DIR_NAME}: cannot remove {ENTRIES_DIR}/{entry}: "
        "Operation not permitted\n"
    )
    assert (cache / "CACHEDIR.TAG").is_file()  # still the cache's, for the next clean


def test_entries_a_running_check_writes_meanwhile_are_named_so_and_the_cache_stays(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A check running while clean works writes new entries between clean's
    listing and its removal of the folder: they are the cache's, not "other
    files", and the folder stays the cache (tagged, ignored by git)."""
    from usdrender_lint.running import result_cache

    _project(tmp_path)
    _checked(tmp_path, ".")
    cache = tmp_path / CACHE_DIR_NAME
    listing = result_cache._entry_files

    def listed_then_written(folder: Path, stale: bool) -> list:
        found = listing(folder, stale)
        (folder / ENTRY).write_text("{}")  # the running check's write, just after
        return found

    monkeypatch.setattr(result_cache, "_entry_files", listed_then_written)
    result = invoke_in(tmp_path, "clean")
    assert result.exit_code == 0, result.output
    assert "other file" not in result.stdout
    assert result.stdout.startswith(f"Cleared {CACHE_DIR_NAME} (1 entry, ")
    assert result.stdout.endswith(
        "kept the folder: a check running meanwhile wrote 1 new entry into it\n"
    )
    assert sorted(p.name for p in cache.iterdir()) == [".gitignore", "CACHEDIR.TAG", ENTRIES_DIR]
    assert _entries(cache) == [ENTRY]
