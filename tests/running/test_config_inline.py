"""``--config 'KEY = VALUE'`` (as ruff's): a setting given as TOML on the command
line, laid over the configuration as a file extending it would be (tables merge by
entry, ``extend-select`` adds), under the flags, for every file of the run."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from cli_support import invoke_in

from usdrender_lint.config import ConfigError, Settings, with_inline

REPO = Path(__file__).resolve().parents[2]
BROKEN = REPO / "examples" / "broken_shot" / "shot.usda"
#: The broken example's findings: CA004, SE007, CA003, SE003 and PR004 (with ST003 info).
FILE = 'fail-on = "warning"\n[severity]\nSE003 = "warning"\n'


def _findings(cwd: Path, *args: str) -> tuple[int, dict[tuple[str, str], str]]:
    """Exit code, and (file name, code) -> severity of each finding."""
    result = invoke_in(cwd, "check", "--jobs", "1", "--format", "json", *args)
    assert result.exit_code in (0, 1), result.output
    files = json.loads(result.stdout)["files"]
    return result.exit_code, {
        (Path(e["file"]).parent.name, f["code"]): f["severity"]
        for e in files
        for f in e["findings"]
    }


@pytest.fixture
def show(tmp_path: Path) -> Path:
    for name in ("a", "b"):
        (tmp_path / name).mkdir()
        shutil.copy(BROKEN, tmp_path / name / "shot.usda")
    (tmp_path / ".usdrender-lint.toml").write_text(FILE)
    (tmp_path / "b" / ".usdrender-lint.toml").write_text('ignore = ["PR004"]\n')
    return tmp_path


def test_a_table_entry_merges_and_the_flags_win(show: Path) -> None:
    status, found = _findings(show, "--no-cache", "a")
    assert status == 1 and found[("a", "CA004")] == "error" and found[("a", "SE003")] == "warning"
    status, found = _findings(
        show, "--no-cache", "a", "--config", 'severity.CA004 = "warning"', "--config",
        'fail-on = "never"',
    )  # fmt: skip
    assert status == 0
    assert found[("a", "CA004")] == "warning"
    assert found[("a", "SE003")] == "warning"  # the file's entry stays
    status, _ = _findings(
        show, "--no-cache", "a", "--config", 'fail-on = "never"', "--fail-on", "error"
    )
    assert status == 1  # the flag over the inline setting


def test_selection_adds_or_starts_over_as_in_a_file_that_extends(show: Path) -> None:
    _, found = _findings(show, "--no-cache", "a", "--config", 'select = ["CA"]')
    assert {code for _, code in found} == {"CA003", "CA004"}
    _, found = _findings(
        show, "--no-cache", "a", "--config", 'select = ["CA"]', "--config", 'extend-select = ["PR"]'
    )
    assert {code for _, code in found} == {"CA003", "CA004", "PR004"}


def test_every_configuration_of_a_split_run_takes_it(show: Path) -> None:
    _, plain = _findings(show, "--no-cache", ".")
    assert ("b", "PR004") not in plain and ("a", "PR004") in plain  # b's own configuration
    _, found = _findings(
        show, "--no-cache", ".", "--config", 'severity.CA003 = "info"', "--show-info"
    )
    assert found[("a", "CA003")] == found[("b", "CA003")] == "info"
    assert ("b", "PR004") not in found  # b's file still applies under it
    _, isolated = _findings(show, "--no-cache", "--isolated", ".", "--config", 'ignore = ["CA"]')
    assert not any(code.startswith("CA") for _, code in isolated)
    assert ("b", "PR004") in isolated  # over the defaults: no file read


def test_the_cache_never_serves_an_answer_of_other_inline_settings(
    show: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("USDRENDER_LINT_NO_CACHE", raising=False)
    fresh = _findings(show, "--no-cache", "a", "--config", 'severity.CA004 = "info"', "--show-info")
    for _ in range(2):  # written, then read
        assert _findings(show, "a") == _findings(show, "--no-cache", "a")
        cached = _findings(show, "a", "--config", 'severity.CA004 = "info"', "--show-info")
        assert cached == fresh


def test_spec_and_merge_take_it_too(show: Path) -> None:
    spec = invoke_in(show, "spec", "--format", "json", "--config", 'profile = "karma"', "a")
    profiles = {s["profile"] for f in json.loads(spec.stdout)["files"] for s in f["settings"]}
    assert profiles == {"karma"}
    shard = invoke_in(show, "check", "--no-cache", "--format", "json", "a").stdout
    (show / "shard.json").write_text(shard)
    merged = invoke_in(show, "merge", "shard.json", "--config", 'fail-on = "never"')
    assert merged.exit_code == 0
    assert invoke_in(show, "merge", "shard.json").exit_code == 1


def test_show_settings_names_it_and_reads_back_as_the_same_settings(show: Path) -> None:
    given = ("--config", 'severity.CA004 = "info"', "--config", 'extend-select = ["UL001"]')
    shown = invoke_in(show, "check", "--show-settings", *given, "a").stdout
    assert "[severity]  # --config 'severity.CA004 = \"info\"'" in shown
    (show / "flat.toml").write_text(shown)
    assert _findings(show, "--no-cache", "--config", "flat.toml", "a") == _findings(
        show, "--no-cache", *given, "a"
    )


@pytest.mark.parametrize(
    ("text", "error"),
    [
        ("selct = 1", "--config 'selct = 1': unknown key 'selct'"),
        ("severity = [", "--config 'severity = [': neither a file nor TOML 'KEY = VALUE': "),
        ('extend = "../x.toml"', "--config 'extend = \"../x.toml\"': 'extend' names a file"),
        ("severity.CA004 = 3", "--config 'severity.CA004 = 3': 'severity.CA004' must be one of"),
        ('fail-on = "sometimes"', "--config 'fail-on = \"sometimes\"': 'fail-on'"),
        (
            'severity.NOPE = "error"',
            "--config 'severity.NOPE = \"error\"': severity.NOPE: no rule has this code",
        ),
        ("rules.XX999.opt = 1", "--config 'rules.XX999.opt = 1': rules.XX999: no rule has"),
    ],
)
def test_a_bad_setting_is_one_line_naming_it(show: Path, text: str, error: str) -> None:
    result = invoke_in(show, "check", "--config", text, "a")
    assert result.exit_code == 2
    (line,) = result.stderr.splitlines()
    assert line.startswith(f"usdrender-lint: error: {error}"), line
    if "no rule" not in error:  # the registry, not the reader, knows the rules
        with pytest.raises(ConfigError):
            with_inline(Settings(), [text])


def test_one_file_at_most(show: Path) -> None:
    (show / "x.toml").write_text("")
    result = invoke_in(show, "check", "--config", "x.toml", "--config", ".usdrender-lint.toml", "a")
    assert result.exit_code == 2
    assert "one configuration file, not 2" in result.output
    # A file whose name holds '=' is a file.
    (show / "k=v.toml").write_text('fail-on = "never"\n')
    assert _findings(show, "--no-cache", "--config", "k=v.toml", "a")[0] == 0
