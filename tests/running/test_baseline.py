"""Baselines: fingerprints that survive edits, counts, bad files, atomic writes."""

from __future__ import annotations

import json
import os
from collections import Counter
from pathlib import Path

import pytest
from click.testing import CliRunner
from fix_support import ONE_MISSING, TWO_MISSING
from pxr import Sdf

from usdrender_lint import atomic
from usdrender_lint.cli import cli
from usdrender_lint.model import FileResult, Finding, Location, Report, Severity
from usdrender_lint.running.baseline import fingerprint, load_baseline, new_findings, write_baseline

SHOT = """#usda 1.0

def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform float4 dataWindowNDC = (0.8, 0, 0.2, 1)
    }
}
"""

# The same opinions with lines moved, comments added and another layout.
SHOT_MOVED = """#usda 1.0
# A comment and blank lines move every line down.



def Scope "Render" {
    def RenderSettings "Settings" {
        uniform float4 dataWindowNDC = (0.8,0,0.2,1)
    }
}
"""

FIXED = SHOT.replace("(0.8, 0, 0.2, 1)", "(0, 0, 1, 1)")

SHOT_WITH_NEW_PROBLEM = SHOT.replace(
    "}\n}\n",
    '}\n\n    def RenderSettings "Second"\n    {\n'
    "        uniform float4 dataWindowNDC = (0.9, 0, 0.1, 1)\n    }\n}\n",
)


def check(*args: str, cwd: Path | None = None):
    runner = CliRunner()
    base = ["check", "--isolated", "--select", "SE003", "--jobs", "1", "--timeout", "0"]
    if cwd is None:
        return runner.invoke(cli, [*base, *args])
    old = os.getcwd()
    os.chdir(cwd)
    try:
        return runner.invoke(cli, [*base, *args])
    finally:
        os.chdir(old)


@pytest.fixture
def shot(tmp_path: Path) -> Path:
    (tmp_path / "shots").mkdir()
    path = tmp_path / "shots" / "shot.usda"
    path.write_text(SHOT, encoding="utf-8")
    return path


def test_write_baseline_records_fingerprints_without_lines(shot, tmp_path) -> None:
    baseline = tmp_path / "baseline.json"
    result = check("--write-baseline", str(baseline), str(shot))
    assert result.exit_code == 0, result.output
    assert "SE003" in result.stdout  # the report is still shown
    document = json.loads(baseline.read_text(encoding="utf-8"))
    assert document["findings"] == [
        {
            "file": "shots/shot.usda",
            "code": "SE003",
            "path": "/Render/Settings.dataWindowNDC",
            "count": 1,
        }
    ]


def test_baseline_hides_known_findings_across_moves_and_reformatting(shot, tmp_path) -> None:
    baseline = tmp_path / "baseline.json"
    assert check(str(shot)).exit_code == 1
    check("--write-baseline", str(baseline), str(shot))

    shot.write_text(SHOT_MOVED, encoding="utf-8")
    result = check("--baseline", str(baseline), str(shot))
    assert result.exit_code == 0, result.output
    assert "SE003" not in result.stdout
    assert "1 finding recorded in" in result.stderr

    # Sdf re-export: USD's own formatting of the same layer.
    Sdf.Layer.FindOrOpen(str(shot)).Export(str(shot))
    assert check("--baseline", str(baseline), str(shot)).exit_code == 0


def test_new_findings_still_fail(shot, tmp_path) -> None:
    baseline = tmp_path / "baseline.json"
    check("--write-baseline", str(baseline), str(shot))
    shot.write_text(SHOT_WITH_NEW_PROBLEM, encoding="utf-8")
    result = check("--format", "json", "--baseline", str(baseline), str(shot))
    assert result.exit_code == 1
    paths = [f["path"] for file in json.loads(result.stdout)["files"] for f in file["findings"]]
    assert paths == ["/Render/Second.dataWindowNDC"]


@pytest.mark.parametrize("timeout", ["0", "60"])  # fixed in this process, or in a worker
def test_fixes_leave_the_findings_the_baseline_records(shot, tmp_path, timeout) -> None:
    """A baseline accepts its findings as they are: --fix and --diff leave them,
    as ruff leaves a noqa'd diagnostic, and fix (or show) only the new ones."""
    baseline = tmp_path / "baseline.json"
    check("--write-baseline", str(baseline), str(shot))
    given = ("--baseline", str(baseline), "--unsafe-fixes", "--timeout", timeout, str(shot))

    nothing_new = check("--diff", *given)
    assert (nothing_new.exit_code, nothing_new.stdout) == (0, ""), nothing_new.output
    assert check("--fix", *given).exit_code == 0
    assert shot.read_text(encoding="utf-8") == SHOT

    shot.write_text(SHOT_WITH_NEW_PROBLEM, encoding="utf-8")
    pending = check("--diff", *given)
    assert pending.exit_code == 1, pending.output
    assert "-        uniform float4 dataWindowNDC = (0.9, 0, 0.1, 1)" in pending.stdout
    assert "(0.8, 0, 0.2, 1)" not in pending.stdout
    fixed = check("--fix", *given)
    assert fixed.exit_code == 0, fixed.output
    assert "no longer occur" not in fixed.stderr
    text = shot.read_text(encoding="utf-8")
    assert "(0.8, 0, 0.2, 1)" in text and "(0.1, 0, 0.9, 1)" in text


def test_paths_are_relative_to_the_baseline_folder(shot, tmp_path) -> None:
    baseline = tmp_path / "baseline.json"
    check("--write-baseline", str(baseline), str(shot))
    # Relative paths from another working directory give the same fingerprints.
    result = check("--baseline", "../baseline.json", "shot.usda", cwd=shot.parent)
    assert result.exit_code == 0, result.output


def test_files_named_through_a_linked_folder_match_the_baseline(shot, tmp_path) -> None:
    link = tmp_path / "link"
    link.symlink_to(tmp_path, target_is_directory=True)
    baseline = tmp_path / "baseline.json"
    check("--write-baseline", str(baseline), str(shot))
    result = check("--baseline", str(link / "baseline.json"), str(link / "shots"))
    assert result.exit_code == 0, result.output
    check("--write-baseline", str(link / "baseline.json"), str(link / "shots"))
    assert json.loads(baseline.read_text())["findings"][0]["file"] == "shots/shot.usda"


def test_a_shard_does_not_write_a_baseline(shot, tmp_path) -> None:
    """A part's findings alone would make every other part's new."""
    baseline = tmp_path / "baseline.json"
    result = check("--shard", "1/2", "--write-baseline", str(baseline), str(shot))
    assert result.exit_code == 2 and not baseline.exists()
    assert result.stderr == (
        "usdrender-lint: error: --write-baseline records every finding of a check: "
        "run it without --shard\n"
    )


#: Two variants of one set, each with its own inverted data window (SE003): the
#: authored one's is seen without --variants, the other's only with it.
SHOT_WITH_VARIANTS = """#usda 1.0
def Scope "Render" (
    variants = {
        string quality = "preview"
    }
    prepend variantSets = "quality"
)
{
    def RenderSettings "Settings"
    {
    }
    variantSet "quality" = {
        "final" {
            over "Settings"
            {
                uniform float4 dataWindowNDC = (0.8, 0, 0.2, 1)
            }
        }
        "preview" {
            over "Settings"
            {
                uniform float4 dataWindowNDC = (0.9, 0, 0.1, 1)
            }
        }
    }
}
"""


def test_variants_keep_the_authored_selections_finding_known(shot, tmp_path) -> None:
    """Was: the other selection's finding (first in the report) took the
    authored one's place in the baseline, which then read as new."""
    shot.write_text(SHOT_WITH_VARIANTS, encoding="utf-8")
    baseline = tmp_path / "baseline.json"
    check("--write-baseline", str(baseline), str(shot))
    result = check("--variants", "--format", "json", "--baseline", str(baseline), str(shot))
    messages = [
        f["message"] for file in json.loads(result.stdout)["files"] for f in file["findings"]
    ]
    assert len(messages) == 1 and "[variant selection: /Render{quality=final}]" in messages[0]
    check("--variants", "--write-baseline", str(baseline), str(shot))
    assert check("--variants", "--baseline", str(baseline), str(shot)).exit_code == 0
    assert check("--baseline", str(baseline), str(shot)).exit_code == 0


def test_a_run_split_by_configuration_counts_every_known_finding(tmp_path) -> None:
    # Two shows with configurations of their own: the run is split in two parts.
    for show in ("a", "b"):
        (tmp_path / show).mkdir()
        (tmp_path / show / "shot.usda").write_text(SHOT, encoding="utf-8")
        (tmp_path / show / ".usdrender-lint.toml").write_text('select = ["SE003"]\n')
    baseline = tmp_path / "baseline.json"
    base = ["check", "--jobs", "1", "--timeout", "0", "--no-cache"]
    runner = CliRunner()
    runner.invoke(cli, [*base, "--write-baseline", str(baseline), str(tmp_path)])
    result = runner.invoke(cli, [*base, "--baseline", str(baseline), str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert result.stderr.splitlines() == [
        f"usdrender-lint: 2 findings recorded in {baseline} not shown"
    ]
    # And every finding gone: the parts' counts are added.
    for show in ("a", "b"):
        (tmp_path / show / "shot.usda").write_text(FIXED, encoding="utf-8")
    result = runner.invoke(cli, [*base, "--baseline", str(baseline), str(tmp_path)])
    assert result.stderr.splitlines() == [
        f"usdrender-lint: 2 findings recorded in {baseline} no longer occur in the files linted: "
        "write the baseline again (--write-baseline) to drop them, or it hides them when they "
        "come back"
    ]


def test_findings_the_baseline_records_that_are_gone_are_counted(shot, tmp_path) -> None:
    """As ESLint's unused suppressions: a fixed finding kept in the baseline
    would be hidden when it came back. Only files linted count, by the rules
    that ran, under other variant selections only with --variants."""
    other = shot.parent / "other.usda"
    other.write_text(SHOT_WITH_NEW_PROBLEM, encoding="utf-8")
    baseline = tmp_path / "baseline.json"
    check("--write-baseline", str(baseline), str(shot.parent))
    gone = f"usdrender-lint: 1 finding recorded in {baseline} no longer occurs in the files linted"
    shot.write_text(FIXED, encoding="utf-8")
    result = check("--baseline", str(baseline), str(shot.parent))
    assert result.exit_code == 0
    assert [line for line in result.stderr.splitlines() if "no longer" in line] == [
        gone + ": write the baseline again (--write-baseline) to drop them, or it hides them "
        "when they come back"
    ]
    # Not counted: a file this run did not lint, a rule it did not run.
    assert "no longer" not in check("--baseline", str(baseline), str(other)).stderr
    unselected = check("--baseline", str(baseline), "--ignore", "SE003", str(shot.parent))
    assert "no longer" not in unselected.stderr


def test_a_baseline_of_other_selections_is_not_gone_without_variants(shot, tmp_path) -> None:
    shot.write_text(SHOT_WITH_VARIANTS, encoding="utf-8")
    baseline = tmp_path / "baseline.json"
    check("--variants", "--write-baseline", str(baseline), str(shot))
    assert "no longer" not in check("--baseline", str(baseline), str(shot)).stderr
    shot.write_text(SHOT_WITH_VARIANTS.replace("0.9, 0, 0.1, 1", "0, 0, 1, 1"), encoding="utf-8")
    assert "no longer" in check("--variants", "--baseline", str(baseline), str(shot)).stderr


def _finding(message: str, path: str = "/Render/S.dataWindowNDC", line: int = 3) -> Finding:
    return Finding(
        "SE003",
        "data-window-malformed",
        Severity.ERROR,
        message,
        Location("/p/a.usda", path, None, line),
    )


def test_fingerprint_ignores_line_and_message() -> None:
    assert fingerprint(_finding("a", line=3), Path("/p")) == fingerprint(
        _finding("b", line=90), Path("/p")
    )
    assert fingerprint(_finding("a"), Path("/p")) == (
        "a.usda",
        "SE003",
        "/Render/S.dataWindowNDC",
        "",
    )


def test_a_second_identical_finding_is_new(tmp_path) -> None:
    baseline = tmp_path / "b.json"
    write_baseline(Report((FileResult("/p/a.usda", findings=(_finding("x"),)),)), baseline)
    later = Report((FileResult("/p/a.usda", findings=(_finding("x"), _finding("y"))),))
    kept, dropped = new_findings(later, load_baseline(baseline), tmp_path)
    assert dropped == 1
    assert [f.message for f in kept.findings] == ["y"]
    relative = os.path.relpath("/p/a.usda", tmp_path)
    key = (relative, "SE003", "/Render/S.dataWindowNDC", "")
    assert load_baseline(baseline) == Counter({key: 1})


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        (None, "baseline file not found (create it with --write-baseline)"),
        ("{not json", "not a baseline file (invalid JSON"),
        ('{"findings": []}', "not a usdrender-lint baseline file"),
        ('{"usdrender_lint_baseline": 9, "findings": []}', "unsupported baseline version 9"),
        ('{"usdrender_lint_baseline": 1, "findings": {}}', "'findings' must be a list"),
        ('{"usdrender_lint_baseline": 1, "findings": [{"file": "a"}]}', "findings[0] lacks"),
        (
            '{"usdrender_lint_baseline": 1, "findings": '
            '[{"file": "a", "code": "SE003", "path": "", "count": 0}]}',
            "findings[0] is malformed",
        ),
        ('{"usdrender_lint_baseline": 1, "findings": ["x"]}', "findings[0] is malformed: 'x'"),
        ('{"usdrender_lint_baseline": 1, "findings": [[1]]}', "findings[0] is malformed: [1]"),
        ('{"usdrender_lint_baseline": true, "findings": []}', "unsupported baseline version True"),
        ('{"usdrender_lint_baseline": 1.0, "findings": []}', "unsupported baseline version 1.0"),
    ],
)
def test_missing_or_corrupt_baseline_is_exit_2(shot, tmp_path, content, expected) -> None:
    baseline = tmp_path / "baseline.json"
    if content is not None:
        baseline.write_text(content, encoding="utf-8")
    result = check("--baseline", str(baseline), str(shot))
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"usdrender-lint: error: {baseline}: ")
    assert expected in lines[0]
    assert result.stdout == ""


def test_a_deeply_nested_baseline_is_one_line(shot, tmp_path) -> None:
    """Was "internal error: RecursionError"."""
    baseline = tmp_path / "baseline.json"
    baseline.write_text("[" * 200_000 + "]" * 200_000, encoding="utf-8")
    result = check("--baseline", str(baseline), str(shot))
    assert result.exit_code == 2 and result.stdout == ""
    assert result.stderr == (
        f"usdrender-lint: error: {baseline}: not a baseline file (JSON nested too deeply)\n"
    )


def test_baseline_and_write_baseline_together_is_exit_2(shot, tmp_path) -> None:
    result = check("--baseline", "a.json", "--write-baseline", "b.json", str(shot))
    assert result.exit_code == 2
    assert "either --baseline or --write-baseline" in result.stderr


def test_unwritable_baseline_is_exit_2(shot, tmp_path) -> None:
    (tmp_path / "a_file").write_text("")  # a missing folder would be created
    result = check("--write-baseline", str(tmp_path / "a_file" / "b.json"), str(shot))
    assert result.exit_code == 2
    assert "cannot write baseline" in result.stderr


def test_writes_are_atomic(tmp_path, monkeypatch) -> None:
    target = tmp_path / "baseline.json"
    target.write_text("old", encoding="utf-8")
    target.chmod(0o640)

    def fail(*_args) -> None:
        raise OSError("disk full")

    monkeypatch.setattr(atomic.os, "replace", fail)
    with pytest.raises(OSError):
        atomic.write_text_atomic(target, "new")
    assert target.read_text(encoding="utf-8") == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["baseline.json"]  # no temporary left
    monkeypatch.undo()

    atomic.write_text_atomic(target, "new")
    assert target.read_text(encoding="utf-8") == "new"
    assert target.stat().st_mode & 0o777 == 0o640


def test_a_second_finding_on_a_recorded_path_is_reported_and_its_fix_is_not_offered(
    tmp_path,
) -> None:
    """The second occurrence is new (counts, as ESLint's suppressions count); --fix
    leaves it with the recorded one, so the report must not call it fixable:
    before, it said "1 fixable with --fix --unsafe-fixes" and --fix changed nothing."""
    shot, baseline = tmp_path / "shot.usda", tmp_path / "baseline.json"
    shot.write_text(ONE_MISSING, encoding="utf-8")
    runner = CliRunner()
    base = ["check", "--isolated", "--select", "PR005", "--jobs", "1", "--timeout", "0"]
    assert runner.invoke(cli, [*base, "--write-baseline", str(baseline), str(shot)]).exit_code == 0
    shot.write_text(TWO_MISSING, encoding="utf-8")
    given = [*base, "--baseline", str(baseline), str(shot)]

    reported = runner.invoke(cli, [*given, "--format", "json"])
    assert reported.exit_code == 1, reported.output
    findings = [f for file in json.loads(reported.stdout)["files"] for f in file["findings"]]
    assert [f["code"] for f in findings] == ["PR005"]
    assert "</Render/Missing2>" in findings[0]["message"]
    text = runner.invoke(cli, given)
    assert text.exit_code == 1
    assert "[unsafe fix, not applied while the baseline records this rule here: remove" in (
        text.stdout
    )
    assert "fixable" not in text.stdout

    diff = runner.invoke(cli, [*given, "--diff", "--unsafe-fixes"])
    assert (diff.exit_code, diff.stdout) == (0, ""), diff.output
    fixed = runner.invoke(cli, [*given, "--fix", "--unsafe-fixes"])
    assert fixed.exit_code == 1, fixed.output
    assert shot.read_text(encoding="utf-8") == TWO_MISSING
    assert "Missing2" in fixed.stdout and "fixable" not in fixed.stdout
