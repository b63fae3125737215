"""``check --show-files`` and ``--show-settings``: what a check would lint, and
with which settings, without linting. The files are those the check's report
names; the settings, read back as a configuration, are the same settings."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from cli_support import invoke_in

REPO = Path(__file__).resolve().parents[2]
BROKEN = REPO / "examples" / "broken_shot" / "shot.usda"

#: Every kind of value a configuration holds: lists, a choice, numbers, booleans,
#: a folder, and tables whose keys need quoting (globs, a quote, non-ASCII).
CONFIG = """\
select = ["CA", "SE003", "PR"]
ignore = ["CA009"]
extend-select = ["ST"]
fail-on = "warning"
time-sample-cap = 12
unfixable = ["camera-target-not-camera"]
max-variant-combinations = 5
profile = "karma"
extend-exclude = ["reference/", "*_backup.usda"]
respect-gitignore = false
force-exclude = true
cache-dir = "lint cache/é"

[severity]
SE003 = "warning"
camera-unset = "info"

[per-path-ignores]
"legacy/**/*.usda" = ["SE"]
'odd "name" é.usda' = ["ALL"]

[per-path-profiles]
"shots/*_rman.usda" = "renderman"

[rules.resolution-non-positive]
require-authored = true
"""


def _invoke(cwd: Path, *args: str) -> tuple[int, str, str]:
    result = invoke_in(cwd, "check", *args)
    return result.exit_code, result.stdout, result.stderr


@pytest.fixture
def project(tmp_path: Path) -> Path:
    for name in ("shots/a/shot.usda", "shots/b/shot.usda", "reference/r.usda", ".hidden/h.usda"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(BROKEN, tmp_path / name)
    (tmp_path / "notes.txt").write_text("not a layer\n")
    return tmp_path


def test_the_settings_read_back_as_a_configuration_are_the_same(project: Path) -> None:
    (project / ".usdrender-lint.toml").write_text(CONFIG, encoding="utf-8")
    status, shown, _ = _invoke(project, "--show-settings", ".")
    assert status == 0, shown
    document = tomllib.loads(shown)
    assert document["fail-on"] == "warning" and document["force-exclude"] is True
    assert document["per-path-ignores"]['odd "name" é.usda'] == ["ALL"]
    assert document["rules"] == {"resolution-non-positive": {"require-authored": True}}
    assert "select" in document and "cache-dir" in document
    # Every key the file set is there with its value.
    given = tomllib.loads(CONFIG)
    assert {key: document[key] for key in given} == given
    # Written out and read as the configuration, the same settings again.
    again = project / "again.toml"
    again.write_text(shown, encoding="utf-8")
    status, shown_again, _ = _invoke(project, "--show-settings", "--config", str(again), ".")
    assert status == 0, shown_again
    assert tomllib.loads(shown_again) == document


def test_each_key_says_where_its_value_came_from(project: Path) -> None:
    (project / ".usdrender-lint.toml").write_text('fail-on = "info"\nvariants = false\n')
    status, shown, _ = _invoke(project, "--show-settings", "--select", "SE003", ".")
    assert status == 0, shown
    lines = {line.split(" = ")[0]: line for line in shown.splitlines() if " = " in line}
    assert lines["select"].endswith("# flag --select")
    assert lines["fail-on"].endswith("# file")
    assert lines["variants"].endswith("# file")  # set in the file, to its default value
    assert lines["profile"].endswith("# default")
    assert f"# configuration file: {project / '.usdrender-lint.toml'}" in shown
    assert "# rules selected: 1 (SE003)" in shown
    status, isolated, _ = _invoke(project, "--show-settings", "--isolated", ".")
    assert "# configuration file: none (the defaults)" in isolated
    assert "# select is not set (default)" in isolated


def _reported(cwd: Path, *args: str) -> list[str]:
    status, stdout, _ = _invoke(cwd, "--no-cache", "--format", "json", *args)
    assert status in (0, 1, 2), stdout  # 2: a file could not be linted
    return [entry["file"] for entry in json.loads(stdout)["files"]]


@pytest.mark.parametrize(
    "args",
    [
        (".",),
        ("shots", "reference/r.usda", ".hidden/h.usda", "notes.txt"),
        ("--force-exclude", "shots", "reference/r.usda", ".hidden/h.usda"),
        ("--extend-exclude", "b/", "."),
        ("--shard", "2/3", "."),
        ("--shard", "1/2", "shots/a/shot.usda", "shots/b/shot.usda", "reference/r.usda"),
        ("missing.usda", "shots"),
    ],
    ids=["walk", "named", "force-exclude", "extend-exclude", "shard", "shard-named", "missing"],
)
def test_the_files_shown_are_the_files_the_check_reports(project: Path, args) -> None:
    (project / ".usdrender-lint.toml").write_text('extend-exclude = ["reference/"]\n')
    status, shown, _ = _invoke(project, "--show-files", *args)
    assert status == 0, shown
    assert shown.splitlines() == _reported(project, *args)
    assert not (project / ".usdrender_lint_cache").exists()  # nothing was linted


def test_with_roots_the_files_shown_are_the_stages_linted(project: Path) -> None:
    layer = project / "shots" / "a" / "lighting.usda"
    layer.write_text("#usda 1.0\n")
    (project / "shots" / "a" / "shot.usda").write_text(
        "#usda 1.0\n(\n    subLayers = [@./lighting.usda@]\n)\n"
    )
    (project / ".usdrender-lint.toml").write_text('roots = ["shots/*/shot.usda"]\n')
    given = str(layer.relative_to(project))
    status, shown, _ = _invoke(project, "--show-files", given)
    assert status == 0
    assert shown.splitlines() == _reported(project, given) == ["shots/a/shot.usda"]


def test_a_bad_configuration_is_one_line_and_exit_2(project: Path) -> None:
    (project / ".usdrender-lint.toml").write_text("selct = []\n")
    for flag in ("--show-files", "--show-settings"):
        run = subprocess.run(
            [sys.executable, "-m", "usdrender_lint", "check", flag, "."],
            cwd=project,
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert run.returncode == 2
        assert run.stdout == ""
        assert run.stderr.strip().splitlines() == [
            f"usdrender-lint: error: {project / '.usdrender-lint.toml'}:1: unknown key 'selct' "
            "(did you mean 'select'?)"
        ]


def test_files_of_nested_configurations_are_shown_in_the_reports_order(tmp_path: Path) -> None:
    # Part after part: p/q and p/s (p's configuration) came before p/r (its own).
    for folder in ("p/q", "p/r", "p/s"):
        (tmp_path / folder).mkdir(parents=True)
        (tmp_path / folder / "x.usda").write_text("#usda 1.0\n")
    (tmp_path / "p" / ".usdrender-lint.toml").write_text('fail-on = "never"\n')
    (tmp_path / "p" / "r" / ".usdrender-lint.toml").write_text('fail-on = "never"\n')
    status, shown, _ = _invoke(tmp_path, "--show-files", ".")
    assert status == 0, shown
    assert shown.splitlines() == ["p/q/x.usda", "p/r/x.usda", "p/s/x.usda"]
    assert shown.splitlines() == _reported(tmp_path, ".")
