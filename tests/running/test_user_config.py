"""The user's own configuration: where no project configuration is found, the
settings of ``$XDG_CONFIG_HOME/usdrender-lint/`` (``~/.config/usdrender-lint/``)
are read, as ruff falls back to ``~/.config/ruff/``
(https://docs.astral.sh/ruff/configuration/#config-file-discovery)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from cli_support import invoke_in

from usdrender_lint.config import load_settings, user_config_dir, user_config_file
from usdrender_lint.running.documents import Documents

SHOT = '#usda 1.0\ndef RenderSettings "S"\n{\n    uniform int2 resolution = (0, 10)\n}\n'


@pytest.fixture
def home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A home folder of the test's own, with no XDG_CONFIG_HOME set."""
    home = tmp_path / "home"
    home.mkdir()
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.delenv("XDG_CONFIG_HOME", raising=False)
    return home


@pytest.fixture
def work(tmp_path: Path) -> Path:
    """A project folder with no configuration, holding one shot."""
    folder = tmp_path / "work" / "shots"
    folder.mkdir(parents=True)
    (folder / "shot.usda").write_text(SHOT)
    return folder.parent


def _codes(cwd: Path, *args: str) -> set[str]:
    result = invoke_in(cwd, "check", "--format", "json", "--jobs", "1", *args)
    assert result.exit_code in (0, 1), result.output
    return {f["code"] for file in json.loads(result.stdout)["files"] for f in file["findings"]}


def test_the_folder_follows_xdg_config_home_else_home(
    home: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert user_config_dir() == home / ".config" / "usdrender-lint"
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "xdg"))
    assert user_config_dir() == tmp_path / "xdg" / "usdrender-lint"
    monkeypatch.setenv("XDG_CONFIG_HOME", "relative/xdg")  # the specification ignores it
    assert user_config_dir() == home / ".config" / "usdrender-lint"


@pytest.mark.parametrize("name", [".usdrender-lint.toml", "usdrender-lint.toml", "pyproject.toml"])
def test_a_check_with_no_project_configuration_reads_the_users(
    home: Path, work: Path, name: str
) -> None:
    assert "SE001" in _codes(work, ".")
    folder = home / ".config" / "usdrender-lint"
    folder.mkdir(parents=True)
    table = "[tool.usdrender-lint]\n" if name == "pyproject.toml" else ""
    (folder / name).write_text(table + 'ignore = ["SE001"]\n')
    assert user_config_file() == folder / name
    assert "SE001" not in _codes(work, ".")
    assert load_settings(start=str(work)).user_level
    # --isolated reads no file, the user's neither; a project's wins over it.
    assert "SE001" in _codes(work, "--isolated", ".")
    (work / ".usdrender-lint.toml").write_text('fail-on = "never"\n')
    assert "SE001" in _codes(work, ".")


def test_xdg_config_home_is_where_it_is_read_from(
    home: Path, work: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    xdg = tmp_path / "xdg"
    (xdg / "usdrender-lint").mkdir(parents=True)
    (xdg / "usdrender-lint" / "usdrender-lint.toml").write_text('ignore = ["SE001"]\n')
    assert "SE001" in _codes(work, ".")  # ~/.config has none
    monkeypatch.setenv("XDG_CONFIG_HOME", str(xdg))
    assert "SE001" not in _codes(work, ".")


def test_its_globs_are_relative_to_the_working_directory(
    home: Path, work: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    folder = home / ".config" / "usdrender-lint"
    folder.mkdir(parents=True)
    (folder / "usdrender-lint.toml").write_text('[per-path-ignores]\n"shots/*.usda" = ["SE001"]\n')
    assert "SE001" not in _codes(work, ".")
    assert "SE001" in _codes(work / "shots", ".")  # there, shots/*.usda names nothing
    # The result cache is at the working directory too, not in ~/.config.
    monkeypatch.delenv("USDRENDER_LINT_NO_CACHE")
    _codes(work, ".")
    assert (work / ".usdrender_lint_cache").is_dir()
    assert not (folder / ".usdrender_lint_cache").exists()


def test_a_folder_without_a_project_configuration_gets_the_users_in_a_split_run(
    home: Path, work: Path
) -> None:
    folder = home / ".config" / "usdrender-lint"
    folder.mkdir(parents=True)
    (folder / "usdrender-lint.toml").write_text('ignore = ["SE001"]\n')
    show = work / "show"
    show.mkdir()
    (show / "shot.usda").write_text(SHOT)
    (show / ".usdrender-lint.toml").write_text('fail-on = "never"\n')
    result = invoke_in(work, "check", "--format", "json", "--jobs", "1", "show", "shots")
    by_file = {
        file["file"]: {f["code"] for f in file["findings"]}
        for file in json.loads(result.stdout)["files"]
    }
    assert "SE001" in by_file["show/shot.usda"]
    assert "SE001" not in by_file["shots/shot.usda"]


def test_a_bad_user_configuration_is_one_line_naming_it(home: Path, work: Path) -> None:
    folder = home / ".config" / "usdrender-lint"
    folder.mkdir(parents=True)
    (folder / "usdrender-lint.toml").write_text("selct = 1\n")
    result = invoke_in(work, "check", ".")
    assert result.exit_code == 2
    assert str(folder / "usdrender-lint.toml") in result.stderr and "selct" in result.stderr


def test_the_language_server_reads_a_user_configuration_created_while_it_runs(
    home: Path, work: Path
) -> None:
    path = str(work / "shots" / "shot.usda")
    documents = Documents()
    documents.update({path: SHOT})
    assert "SE001" in {f.code for f in documents.lint(path).findings}
    folder = home / ".config" / "usdrender-lint"
    folder.mkdir(parents=True)
    (folder / "usdrender-lint.toml").write_text('ignore = ["SE001"]\n')
    assert "SE001" not in {f.code for f in documents.lint(path).findings}


def test_show_settings_says_it_is_the_users_own(home: Path, work: Path) -> None:
    folder = home / ".config" / "usdrender-lint"
    folder.mkdir(parents=True)
    (folder / "usdrender-lint.toml").write_text('ignore = ["SE001"]\n')
    result = invoke_in(work, "check", "--show-settings", ".")
    first = result.stdout.splitlines()[0]
    assert str(folder / "usdrender-lint.toml") in first and "the user's own" in first


def test_show_settings_without_one_says_where_it_looked(home: Path, work: Path) -> None:
    """Before, "none (the defaults)" alone: a file of another name in the folder
    (ruff's ruff.toml copied over) was ignored without a word anywhere."""
    folder = home / ".config" / "usdrender-lint"
    first = invoke_in(work, "check", "--show-settings", ".").stdout.splitlines()[0]
    assert first == (
        "# configuration file: none (the defaults: no project configuration found, and none "
        f"of your own in {folder})"
    )
    folder.mkdir(parents=True)
    (folder / "ruff.toml").write_text('ignore = ["SE001"]\n')
    first = invoke_in(work, "check", "--show-settings", ".").stdout.splitlines()[0]
    assert first.endswith(
        f"none of your own in {folder}; ruff.toml there is not read: name it "
        ".usdrender-lint.toml, usdrender-lint.toml or pyproject.toml)"
    )
    isolated = invoke_in(work, "check", "--show-settings", "--isolated", ".").stdout
    assert isolated.splitlines()[0] == "# configuration file: none (the defaults)"
