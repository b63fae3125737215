"""The Python API: usdrender_lint.lint_file / lint_stage."""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
from pathlib import Path

import pytest
from pxr import Usd

import usdrender_lint
from usdrender_lint.config import ConfigError, Settings
from usdrender_lint.model import Finding, Report, Severity

REPO = Path(__file__).parents[2]
SE003 = REPO / "tests" / "rules" / "SE003_data_window_malformed"
FAIL = SE003 / "fail_inverted.usda"


def pairs(report: Report) -> set[tuple[str, str]]:
    return {(f.code, f.location.path or "") for f in report.findings}


def test_lint_file_returns_plain_frozen_findings() -> None:
    report = usdrender_lint.lint_file(FAIL)
    assert isinstance(report, Report)
    assert ("SE003", "/Render/Settings.dataWindowNDC") in pairs(report)
    finding = next(f for f in report.findings if f.code == "SE003")
    assert isinstance(finding, Finding) and finding.severity is Severity.ERROR
    assert finding.location.file == str(FAIL)
    with pytest.raises(dataclasses.FrozenInstanceError):
        finding.code = "X"  # type: ignore[misc]
    assert {r.code for r in report.rules} >= {"SE003", "CA001"}


def test_lint_file_matches_the_command_line() -> None:
    from click.testing import CliRunner

    from usdrender_lint.cli import cli

    result = CliRunner().invoke(cli, ["check", "--isolated", "--format", "json", str(FAIL)])
    document = json.loads(result.output)
    cli_pairs = {(f["code"], f["path"] or "") for f in document["files"][0]["findings"]}
    assert pairs(usdrender_lint.lint_file(FAIL)) == cli_pairs


def test_select_and_ignore() -> None:
    assert {code for code, _ in pairs(usdrender_lint.lint_file(FAIL, select=["SE"]))} == {
        "SE003",
        "SE015",
    }
    ignored = usdrender_lint.lint_file(FAIL, ignore=["SE003", "no-products"])
    assert {"SE003", "SE015"}.isdisjoint(code for code, _ in pairs(ignored))
    assert [r.code for r in usdrender_lint.lint_file(FAIL, select="SE003").rules] == ["SE003"]


def test_config_file_and_settings(tmp_path: Path) -> None:
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text('ignore = ["SE003"]\n[severity]\nSE015 = "warning"\n')
    report = usdrender_lint.lint_file(FAIL, config=config)
    assert "SE003" not in {f.code for f in report.findings}
    assert next(f for f in report.findings if f.code == "SE015").severity is Severity.WARNING
    # The keywords are laid over the file as flags are (ruff's layers): ignore=
    # adds to its ignore list, extend_select= brings back a rule it ignores.
    assert "SE003" not in {
        f.code for f in usdrender_lint.lint_file(FAIL, config=config, ignore=[]).findings
    }
    again = usdrender_lint.lint_file(FAIL, config=config, extend_select=["SE003"])
    assert "SE003" in {f.code for f in again.findings}
    settings = Settings(per_path_ignores={"*.usda": ("SE",)})
    assert not any(
        f.code.startswith("SE") for f in usdrender_lint.lint_file(FAIL, config=settings).findings
    )


def test_a_config_table_lints_as_the_same_table_in_a_file(tmp_path: Path) -> None:
    table = {
        "ignore": ["SE003"],
        "severity": {"SE015": "warning"},
        "per-path-ignores": {"*.usda": ["PR"]},
    }
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text(
        'ignore = ["SE003"]\n[per-path-ignores]\n"*.usda" = ["PR"]\n[severity]\nSE015 = "warning"\n'
    )
    from_table = usdrender_lint.lint_file(FAIL, config=table)
    assert from_table.findings == usdrender_lint.lint_file(FAIL, config=config).findings
    assert "SE003" not in {f.code for f in from_table.findings}
    assert next(f for f in from_table.findings if f.code == "SE015").severity is Severity.WARNING
    stage = Usd.Stage.Open(str(FAIL))
    assert usdrender_lint.lint_stage(stage, config=table).findings == from_table.findings
    # The keywords are laid over the table, as flags over a file.
    assert "SE003" in {
        f.code for f in usdrender_lint.lint_file(FAIL, config=table, select=["SE"]).findings
    }
    with pytest.raises(ConfigError, match="^config: unknown key 'nope'$"):
        usdrender_lint.lint_file(FAIL, config={"nope": 1})
    with pytest.raises(ConfigError, match="^config: 'fail-on'"):
        usdrender_lint.lint_stage(stage, config={"fail-on": 3})
    # An API caller has no --config flag: the file is the config argument.
    with pytest.raises(
        ConfigError, match=r"^config: 'extend' names a file: pass the file as config=PATH$"
    ):
        usdrender_lint.lint_file(FAIL, config={"extend": str(tmp_path / "base.toml")})


def test_bad_configuration_raises_config_error(tmp_path: Path) -> None:
    # A value passed is named by its keyword, not by the command line's flag.
    with pytest.raises(ConfigError, match="^argument select: 'NOPE' matches no rule"):
        usdrender_lint.lint_file(FAIL, select=["NOPE"])
    with pytest.raises(ConfigError, match="^argument extend_select: 'NOPE' matches no rule"):
        usdrender_lint.lint_stage(Usd.Stage.Open(str(FAIL)), extend_select=["NOPE"])
    with pytest.raises(ConfigError, match="^argument profile: unknown profile 'x'"):
        usdrender_lint.lint_file(FAIL, profile="x")
    with pytest.raises(ConfigError, match="^argument max_variant_combinations must be"):
        usdrender_lint.lint_file(FAIL, variants=True, max_variant_combinations=0)
    with pytest.raises(ConfigError, match="^argument variants must be true or false"):
        usdrender_lint.lint_file(FAIL, variants="yes")  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match="^argument select must be a list of strings"):
        usdrender_lint.lint_file(FAIL, select=[1])  # type: ignore[list-item]
    broken = tmp_path / ".usdrender-lint.toml"
    broken.write_text("fail-on = 3\n")
    with pytest.raises(ConfigError, match="fail-on"):
        usdrender_lint.lint_file(FAIL, config=broken)


def test_a_missing_file_is_an_error_result_not_an_exception(tmp_path: Path) -> None:
    report = usdrender_lint.lint_file(tmp_path / "nope.usda")
    assert report.files[0].status == "error"
    assert "no such file" in report.files[0].error


def test_lint_stage_sees_unsaved_edits_and_writes_nothing() -> None:
    before = FAIL.read_bytes()
    stage = Usd.Stage.Open(str(FAIL))
    assert "SE003" in {f.code for f in usdrender_lint.lint_stage(stage).findings}
    settings = stage.GetPrimAtPath("/Render/Settings")
    # An unsaved edit (in the session layer, so no other test sees a dirty layer).
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        settings.GetAttribute("dataWindowNDC").Set((0.0, 0.0, 1.0, 1.0))
    report = usdrender_lint.lint_stage(stage, select=["SE003"], file="shot")
    assert report.findings == ()
    assert report.files[0].file == "shot"
    assert not stage.GetRootLayer().dirty
    assert FAIL.read_bytes() == before


def test_lint_stage_names_the_root_layer_by_default() -> None:
    stage = Usd.Stage.Open(str(FAIL))
    assert usdrender_lint.lint_stage(stage).files[0].file == str(FAIL.resolve())


def test_a_profile_keyword_is_the_reason_the_findings_name() -> None:
    # The reason read "--profile karma", a flag the caller never gave.
    by_keyword = {
        f.profile_reason
        for report in (
            usdrender_lint.lint_file(FAIL, profile="karma"),
            usdrender_lint.lint_stage(Usd.Stage.Open(str(FAIL)), profile="karma"),
        )
        for f in report.findings
    }
    assert by_keyword == {"argument profile = karma"}
    # The configuration's profile keeps its own reason.
    in_config = usdrender_lint.lint_file(FAIL, config={"profile": "karma"})
    assert {f.profile_reason for f in in_config.findings} == {"config: profile = karma"}


def test_unknown_attribute_is_an_attribute_error() -> None:
    with pytest.raises(AttributeError):
        usdrender_lint.lint_everything  # noqa: B018


def test_the_api_imports_neither_click_nor_rich_and_import_is_cheap() -> None:
    script = f"""
import json, sys
import usdrender_lint
cheap = "pxr" not in sys.modules
report = usdrender_lint.lint_file({str(FAIL)!r})
print(json.dumps({{"cheap": cheap, "found": len(report.findings),
                  "heavy": sorted(m for m in ("click", "rich") if m in sys.modules)}}))
"""
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    got = json.loads(done.stdout)
    assert got == {"cheap": True, "found": got["found"], "heavy": []}
    assert got["found"] > 0


def test_the_package_is_typed() -> None:
    assert (Path(usdrender_lint.__file__).parent / "py.typed").is_file()
    hints = usdrender_lint.lint_file.__annotations__
    assert hints["return"] in ("Report", Report)


def test_a_folder_is_walked_as_check_walks_it() -> None:
    """As the guide says: one result per USD file below the folder."""
    report = usdrender_lint.lint_file(SE003)
    walked = sorted(Path(result.file).name for result in report.files)
    assert walked == sorted(p.name for p in SE003.iterdir() if p.suffix == ".usda")
    assert all(result.status == "linted" for result in report.files)
