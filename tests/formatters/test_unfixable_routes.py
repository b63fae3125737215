"""A rule the configuration makes ``unfixable`` offers no fix on any route: every
report format, the Python API (a file and an open stage) and the validation
plugins' findings, as ``--fix`` applies none. Ruff drops such a rule's fix from
its diagnostics too (https://github.com/astral-sh/ruff/pull/7919).

The example shot has two findings with a safe fix, CA004 and SE007; the
configuration makes CA004 unfixable: its fix must show nowhere, SE007's
everywhere.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner
from pxr import Usd

from usdrender_lint import lint_file, lint_stage
from usdrender_lint.cli import cli
from usdrender_lint.model import FileResult, Report
from usdrender_lint.running.stage_lints import CheckLinters, StageLints

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "broken_shot"
#: The fixes' descriptions, as each format shows them.
CA004_FIX = "retarget camera to"
SE007_FIX = "replace with disableMotionBlur"
FORMATS = ("text", "full", "json", "sarif", "junit", "html")


@pytest.fixture
def shot(tmp_path: Path) -> Path:
    for name in ("shot.usda", "lighting_wip.usda"):
        (tmp_path / name).write_text((EXAMPLE / name).read_text())
    (tmp_path / ".usdrender-lint.toml").write_text('unfixable = ["CA004"]\n')
    return tmp_path / "shot.usda"


@pytest.mark.parametrize("output", FORMATS)
def test_no_format_offers_the_fix_of_an_unfixable_rule(shot: Path, output: str) -> None:
    # JSON, SARIF, JUnit and HTML carried CA004's fix while --fix applies none
    # (and the text report said "[fix, unfixable in the configuration: ...]").
    done = CliRunner().invoke(
        cli, ["check", "--no-cache", "--jobs", "1", "--format", output, str(shot)]
    )
    assert "CA004" in done.stdout
    assert SE007_FIX in done.stdout
    assert CA004_FIX not in done.stdout


def test_the_json_report_s_fix_is_null_for_an_unfixable_rule(shot: Path) -> None:
    done = CliRunner().invoke(cli, ["check", "--no-cache", "--format", "json", str(shot)])
    fixes = {f["code"]: f["fix"] for f in json.loads(done.stdout)["files"][0]["findings"]}
    assert fixes["CA004"] is None
    assert fixes["SE007"] is not None and fixes["SE007"]["safe"] is True


def test_every_route_gives_the_findings_of_check(shot: Path) -> None:
    """The same file and configuration through check's JSON, the Python API's
    lint_file and lint_stage (given the configuration), and the findings the
    validation plugins report (running/stage_lints): one answer, fixes included."""
    done = CliRunner().invoke(cli, ["check", "--no-cache", "--format", "json", str(shot)])
    checked = sorted(
        (f["code"], f["path"], f["message"], json.dumps(f["fix"], sort_keys=True))
        for f in json.loads(done.stdout)["files"][0]["findings"]
    )

    def keyed(findings) -> list[tuple]:
        return sorted(
            (
                f.code,
                f.location.path,
                f.message,
                json.dumps(
                    {"description": f.fix.description, "safe": f.fix.safe} if f.fix else None,
                    sort_keys=True,
                ),
            )
            for f in findings
        )

    config = shot.parent / ".usdrender-lint.toml"
    stage = Usd.Stage.Open(str(shot))
    assert keyed(lint_file(shot, config=config).findings) == checked
    assert keyed(lint_stage(stage, config=config).findings) == checked
    hosts = CheckLinters()
    traced = hosts.reported(stage, StageLints(hosts.linter, hosts.lint).findings(stage))
    assert keyed(t.finding for t in traced) == checked
    assert any(code == "CA004" for code, *_ in checked)


def test_the_sarif_run_describes_an_unfixable_rule_without_a_fix(shot: Path) -> None:
    # tool.driver.rules[] said CA004's class ("safe-conditional") while its
    # results carry no fix and --fix applies none: the run offers none.
    done = CliRunner().invoke(cli, ["check", "--no-cache", "--format", "sarif", str(shot)])
    described = {
        rule["id"]: rule["properties"]["fix"]
        for rule in json.loads(done.stdout)["runs"][0]["tool"]["driver"]["rules"]
    }
    assert described["CA004"] == "none"
    assert described["SE007"] == "safe-conditional"


def test_a_rule_unfixable_in_one_part_of_a_split_run_keeps_its_fix_class() -> None:
    # Its fixes are offered in the other part's files.
    report = Report(
        (FileResult("a.usda"), FileResult("b.usda")),
        unfixable=frozenset({"CA004", "SE007"}),
        unfixable_by_file=(
            ("a.usda", frozenset({"CA004"})),
            ("b.usda", frozenset({"CA004", "SE007"})),
        ),
    )
    assert report.unfixable_everywhere() == {"CA004"}
    assert Report(unfixable=frozenset({"SE007"})).unfixable_everywhere() == {"SE007"}
