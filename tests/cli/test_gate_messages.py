"""What a gate says: it shows what fails, it refuses what it cannot do, and
its messages carry no machine's absolute paths.

- ``--fail-on info`` shows the info findings it fails on, in text and in
  GitHub annotations (it failed with "0 findings (2 info hidden)").
- ``--ignore ST001`` is refused with a message (a file USD cannot open is
  never a silent pass); a wider selector (``ALL``, ``ST``) says so in a note.
- ST001's message does not repeat the file's absolute path: the location
  carries the file, line and column.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli

REPO = Path(__file__).resolve().parents[2]
INFO_ONLY = REPO / "tests" / "rules" / "ST003_render_settings_path_missing" / "fail_unset.usda"
WIP = REPO / "examples" / "broken_shot" / "lighting_wip.usda"


def check(*args: str):
    return CliRunner().invoke(cli, ["check", "--isolated", *args])


def test_fail_on_info_shows_the_info_findings_in_text() -> None:
    result = check("--select", "ST003", "--fail-on", "info", str(INFO_ONLY))
    assert result.exit_code == 1
    assert "info ST003" in result.stdout
    assert "hidden" not in result.stdout
    assert "1 finding in 1 file" in result.stdout


def test_fail_on_info_annotates_them_on_github() -> None:
    result = check("--select", "ST003", "--format", "github", "--fail-on", "info", str(INFO_ONLY))
    assert result.exit_code == 1
    assert result.stdout.startswith("::notice file=") and "title=ST003::" in result.stdout


def test_the_default_gate_still_hides_info() -> None:
    result = check("--select", "ST003", str(INFO_ONLY))
    assert result.exit_code == 0
    assert "1 info hidden" in result.stdout


@pytest.mark.parametrize("selector", ["ST001", "st001", "stage-open-failed"])
def test_ignoring_st001_itself_is_refused(selector: str) -> None:
    result = check("--ignore", selector, str(WIP))
    assert result.exit_code == 2
    assert result.stderr.count("\n") == 1
    assert f"--ignore: {selector!r} cannot be ignored: ST001 (stage-open-failed)" in result.stderr


def test_ignoring_st001_in_the_config_is_refused(tmp_path: Path) -> None:
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text('ignore = ["ST001"]\n')
    result = CliRunner().invoke(cli, ["check", "--config", str(config), str(WIP)])
    assert result.exit_code == 2
    assert "'ST001' cannot be ignored" in result.stderr


@pytest.mark.parametrize("selector", ["ALL", "ST"])
def test_a_wider_ignore_says_st001_stays(selector: str) -> None:
    result = check("--ignore", selector, "--format", "json", str(WIP))
    assert result.exit_code == 1
    codes = [f["code"] for f in json.loads(result.stdout)["files"][0]["findings"]]
    assert codes == ["ST001"]
    assert f"note: ignore {selector!r}: ST001 (stage-open-failed) is always reported" in (
        result.stderr
    )


@pytest.mark.parametrize("output_format", ["json", "sarif", "github", "text"])
def test_st001_does_not_repeat_the_absolute_path(output_format: str) -> None:
    result = check("--format", output_format, str(WIP))
    assert result.exit_code == 1
    assert "Expected } at '' in </Lights/key>" in result.stdout
    # The file is named once per finding (where the format names it), not in the message.
    assert f"{WIP}:9:1: Expected" not in result.stdout
    if output_format == "json":
        (finding,) = json.loads(result.stdout)["files"][0]["findings"]
        assert finding["message"] == "Expected } at '' in </Lights/key>"
        assert (finding["line"], finding["column"]) == (9, 1)
