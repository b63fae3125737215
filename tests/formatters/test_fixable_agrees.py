"""Every report of one run agrees on which findings are fixable: one configured
project (a rule made ``unfixable``, a ``--baseline`` that holds a new finding's
fix back) through every output format. A format says a finding is fixable when
it offers its fix (the text, HTML and JUnit reports show a held fix marked, as
``--fix`` leaves it); the summaries count the same findings.

The project: the example shot (CA004 with a safe fix the configuration makes
unfixable, SE007 with a safe fix, SE003 with an unsafe one) and a product
whose second missing orderedVars target is new on a relationship where the
baseline records the first (PR005: reported, its unsafe fix held back).
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path
from xml.etree import ElementTree

import pytest
from click.testing import CliRunner
from fix_support import ONE_MISSING, TWO_MISSING

from usdrender_lint.cli import cli

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "broken_shot"
#: What ``--fix --unsafe-fixes`` would fix: each finding's code and whether it is safe.
FIXABLE = {"SE007": True, "SE003": False}
#: Reported without a fix on offer: CA004 (unfixable), PR005 (held by the baseline).
REPORTED = frozenset({"CA004", "SE007", "SE003", "PR005"})
HELD = "not applied while the baseline records this rule here"


@pytest.fixture
def project(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The check's arguments, run from the project's folder."""
    for name in ("shot.usda", "lighting_wip.usda"):
        shutil.copy(EXAMPLE / name, tmp_path / name)
    (tmp_path / ".usdrender-lint.toml").write_text(
        'select = ["CA004", "SE007", "SE003", "PR005"]\nunfixable = ["CA004"]\n'
    )
    (tmp_path / "beauty.usda").write_text(ONE_MISSING)
    monkeypatch.chdir(tmp_path)
    base = ["check", "--no-cache", "--jobs", "1", "--timeout", "0"]
    written = CliRunner().invoke(cli, [*base, "--write-baseline", "baseline.json", "beauty.usda"])
    assert written.exit_code == 0, written.output
    (tmp_path / "beauty.usda").write_text(TWO_MISSING)
    return [*base, "--baseline", "baseline.json", "shot.usda", "beauty.usda"]


def _report(args: list[str], fmt: str) -> str:
    done = CliRunner().invoke(cli, [*args, "--format", fmt])
    assert done.exit_code == 1, done.output
    return done.stdout


def _text_fixes(stdout: str, reported: frozenset[str] = REPORTED) -> dict[str, bool]:
    offered = {}
    assert (
        set(re.findall(r"^\S+: (?:error|warning|info) ([A-Z]{2}\d{3}) ", stdout, re.M)) == reported
    )
    for line in stdout.splitlines():
        found = re.search(r" ([A-Z]{2}\d{3}) .*\[(unsafe )?fix(, [^:]*)?: ", line)
        if found and not found.group(3):
            offered[found.group(1)] = not found.group(2)
        if found and found.group(3):
            assert found.group(3) == f", {HELD}", line
    return offered


def _json_fixes(stdout: str, reported: frozenset[str] = REPORTED) -> dict[str, bool]:
    findings = [f for file in json.loads(stdout)["files"] for f in file["findings"]]
    assert {f["code"] for f in findings} == reported
    return {f["code"]: f["fix"]["safe"] for f in findings if f["fix"] is not None}


def _sarif_fixes(stdout: str, reported: frozenset[str] = REPORTED) -> dict[str, bool]:
    results = json.loads(stdout)["runs"][0]["results"]
    assert {r["ruleId"] for r in results} == reported
    return {
        r["ruleId"]: r["properties"]["fix"]["safe"]
        for r in results
        if "fix" in r.get("properties", {})
    }


def _junit_fixes(stdout: str, reported: frozenset[str] = REPORTED) -> dict[str, bool]:
    offered = {}
    failures = list(ElementTree.fromstring(stdout).iter("failure"))
    assert {f.get("type") for f in failures} == reported
    for failure in failures:
        for line in (failure.text or "").splitlines():
            found = re.match(r"(unsafe )?fix(, [^:]*)?: ", line)
            if found and not found.group(2):
                offered[failure.get("type")] = not found.group(1)
    return offered


def _html_fixes(stdout: str, reported: frozenset[str] = REPORTED) -> dict[str, bool]:
    offered = {}
    entries = [
        (re.findall(r'data-code="([^"]+)"', entry)[0], entry)
        for entry in stdout.split('<li class="finding"')[1:]
    ]
    assert {code for code, _entry in entries} == reported
    for code, entry in entries:
        tag = re.search(r'<p class="fix"><span class="tag">([^<]*)</span>', entry)
        if tag and HELD not in tag.group(1):
            offered[code] = tag.group(1) == "fix"
        if tag and HELD in tag.group(1):
            assert '<pre class="diff">' not in entry  # no diff of a fix --diff leaves
    return offered


READERS = {
    "text": _text_fixes,
    "full": _text_fixes,
    "json": _json_fixes,
    "sarif": _sarif_fixes,
    "junit": _junit_fixes,
    "html": _html_fixes,
}


@pytest.mark.parametrize("fmt", sorted(READERS))
def test_every_format_offers_the_fixes_fix_would_apply(project: list[str], fmt: str) -> None:
    # JSON, SARIF and HTML offered PR005's fix that the baseline holds back (JUnit
    # too, unmarked), while the text report marked it and counted it not.
    assert READERS[fmt](_report(project, fmt)) == FIXABLE


def test_the_summaries_count_the_fixes_offered(project: list[str]) -> None:
    safe = sum(FIXABLE.values())
    unsafe = len(FIXABLE) - safe
    text = _report(project, "text").splitlines()[-1]
    assert text.endswith(f"; {safe} fixable with --fix ({unsafe} more with --unsafe-fixes).")
    html = _report(project, "html")
    assert f'<span class="chip">{safe} fixable with --fix, {unsafe} more unsafe</span>' in html


def test_the_github_and_gitlab_reports_offer_no_fix(project: list[str]) -> None:
    # Neither format carries fixes: no held or unfixable fix shows up in them.
    for fmt in ("github", "gitlab"):
        shown = _report(project, fmt)
        assert "remove </Render/Missing2>" not in shown and "retarget" not in shown


@pytest.mark.parametrize("fmt", sorted(READERS))
def test_merge_config_offers_the_fixes_check_under_it_offers(project: list[str], fmt: str) -> None:
    # A report linted under another configuration (--isolated: CA004 fixable),
    # merged with --config naming the project's: CA004's fix was offered again.
    at = project.index("--baseline")
    isolated = [*project[:at], "--isolated", "--select", "CA004,SE007,SE003,PR005", *project[at:]]
    CliRunner().invoke(cli, [*isolated, "--format", "json", "--output", "run.json"])
    merged = CliRunner().invoke(
        cli, ["merge", "--config", ".usdrender-lint.toml", "--format", fmt, "run.json"]
    )
    assert merged.exit_code == 1, merged.output
    assert READERS[fmt](merged.stdout) == FIXABLE


@pytest.mark.parametrize("fmt", sorted(READERS))
def test_a_held_fix_whose_message_names_a_file_stays_held(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fmt: str
) -> None:
    # The report writes a message's absolute paths relative to the working
    # directory; the finding so renamed was no longer among those the baseline
    # holds back, and every format offered its fix (a plugin rule's message
    # that quotes a layer's path).
    from usdrender_lint.cli.check import emit_report
    from usdrender_lint.formatters import FormatOptions
    from usdrender_lint.model import FileResult, Finding, FixInfo, Location, Report, Severity

    monkeypatch.chdir(tmp_path)
    layer = str(tmp_path / "beauty.usda")
    held = Finding(
        "PR005",
        "ordered-vars-invalid-target",
        Severity.ERROR,
        f"orderedVars target </Render/Missing2> of @{layer}@ does not exist",
        Location(layer, "/Render/Beauty.orderedVars", layer, 8),
        FixInfo("remove </Render/Missing2> from orderedVars", safe=False),
    )
    report = Report((FileResult(layer, findings=(held,)),), baseline_held=frozenset({held}))
    emit_report(report, fmt, [], FormatOptions(show_info=True), "out")
    shown = (tmp_path / "out").read_text(encoding="utf-8")
    assert "@beauty.usda@" in shown
    assert READERS[fmt](shown, frozenset({"PR005"})) == {}


@pytest.mark.parametrize("fmt", ["text", "junit", "json", "sarif"])
def test_merged_shards_hold_back_the_fix_the_baseline_holds_back(
    project: list[str], fmt: str
) -> None:
    # Each shard may read the baseline; the JSON report wrote a held fix as
    # null, and the merged text report lost its mark (check's said "not applied
    # while the baseline records this rule here").
    shards = []
    for k in (1, 2):
        done = CliRunner().invoke(
            cli, [*project, "--shard", f"{k}/2", "--format", "json", "--output", f"{k}.json"]
        )
        assert done.exit_code in (0, 1), done.output
        shards.append(f"{k}.json")
    merged = CliRunner().invoke(cli, ["merge", "--format", fmt, *shards])
    assert merged.exit_code == 1, merged.output
    assert merged.stdout == _report(project[:-2] + ["beauty.usda", "shot.usda"], fmt)
