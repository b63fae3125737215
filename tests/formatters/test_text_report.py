"""The text report as terminals, editors and problem matchers read it: one line
per finding, ``path:line:col:`` first (the layer holding the opinion), sorted,
wrapped at words on a terminal, and a summary that counts what --fix would fix."""

from __future__ import annotations

import io
import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.formatters import FormatOptions
from usdrender_lint.formatters.text import INDENT, TextFormatter
from usdrender_lint.model import FileResult, Finding, FixInfo, Location, Report, Severity

REPO = Path(__file__).resolve().parents[2]
MATCHER = REPO / "examples" / "usdrender-lint-problem-matcher.json"
#: Where a finding line's location ends: ``file:``, ``file:line:`` or ``file:line:col:``.
LOCATION = re.compile(r"^(?P<file>[^:]+):(?:(?P<line>\d+):)?(?:(?P<col>\d+):)? ")

SHOT = """#usda 1.0
(
    subLayers = [@./lighting.usda@]
)
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform float pixelAspectRatio = 0
    }
}
"""
LIGHTING = """#usda 1.0
over "Render"
{
    over "Settings"
    {
        uniform float4 dataWindowNDC = (1, 1, 0, 0)
        uniform token[] includedPurposes = ["default", "default"]
    }
}
"""
BROKEN = '#usda 1.0\ndef Scope "A"\n{\n    def Scope "B" {\n'


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.fixture
def shot(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    (tmp_path / "shots").mkdir()
    (tmp_path / "shots" / "shot.usda").write_text(SHOT)
    (tmp_path / "shots" / "lighting.usda").write_text(LIGHTING)
    (tmp_path / "shots" / "broken.usda").write_text(BROKEN)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def check(*args: str):
    return CliRunner().invoke(cli, ["check", "--isolated", "--jobs", "1", *args])


def finding_lines(output: str) -> list[str]:
    return output.splitlines()[:-1]  # the last line is the summary


def test_each_line_starts_with_the_layer_and_line_relative_to_the_working_directory(
    shot: Path,
) -> None:
    result = check("--select", "SE002,SE003,SE009,ST001", "shots")
    lines = finding_lines(result.stdout)
    assert lines == sorted(lines, key=lambda line: (line.split(":")[0], int(line.split(":")[1])))
    assert [line.split(" ", 2)[:2] for line in lines] == [
        ["shots/broken.usda:5:1:", "error"],
        ["shots/lighting.usda:6:", "error"],  # the sublayer holds the opinion
        ["shots/lighting.usda:7:", "warning"],
        ["shots/shot.usda:9:", "error"],
    ]
    assert lines[0].startswith("shots/broken.usda:5:1: error ST001: ")
    assert str(shot) not in lines[0]  # USD's own position prefix is not repeated
    assert lines[1].startswith(
        "shots/lighting.usda:6: error SE003 /Render/Settings.dataWindowNDC: dataWindowNDC "
    )
    # A finding in a layer of a stage names the stage it was linted in.
    assert lines[1].endswith("(stage shots/shot.usda)")
    assert "(stage" not in lines[3]


def test_a_finding_without_a_line_names_the_file_alone() -> None:
    finding = Finding(
        "ST003", "x", Severity.ERROR, "no path", Location("/elsewhere/a.usdc", None, None, None)
    )
    stream = io.StringIO()
    TextFormatter().render(
        Report((FileResult("/elsewhere/a.usdc", findings=(finding,)),)), stream, FormatOptions()
    )
    assert stream.getvalue().splitlines()[0] == "/elsewhere/a.usdc: error ST003: no path"


def test_findings_are_sorted_by_file_line_then_code() -> None:
    def finding(code: str, layer: str, line: int | None) -> Finding:
        return Finding(code, "n", Severity.ERROR, "m", Location("z.usda", "/P", layer, line))

    report = Report(
        (
            FileResult(
                "z.usda",
                findings=(
                    finding("SE003", "b.usda", 3),
                    finding("CA004", "b.usda", 3),
                    finding("AA001", "b.usda", 12),
                    finding("ZZ001", "a.usda", 40),
                    finding("SE001", "b.usda", None),
                ),
            ),
        )
    )
    stream = io.StringIO()
    TextFormatter().render(report, stream, FormatOptions())
    assert [line.split(" /P")[0] for line in finding_lines(stream.getvalue())] == [
        "a.usda:40: error ZZ001",
        "b.usda: error SE001",
        "b.usda:3: error CA004",
        "b.usda:3: error SE003",
        "b.usda:12: error AA001",
    ]


LONG = Finding(
    "CA004",
    "camera-target-not-camera",
    Severity.ERROR,
    "camera target </World/camRig> is an Xform, not a Camera; target the Camera "
    "</World/camRig/shotCam> instead, " * 3,
    Location("shots/010/shot.usda", "/Render/PrimarySettings.camera", "shots/010/shot.usda", 32),
    FixInfo("retarget camera to </World/camRig/shotCam>", True),
)
DEEP = Finding(
    "SE003",
    "data-window-malformed",
    Severity.ERROR,
    "dataWindowNDC is inverted " * 8,
    Location("x.usda", "/R/S.dataWindowNDC", "a/" + "very_long_folder_name/" * 6 + "x.usda", 7),
)


@pytest.mark.parametrize("width", [80, 60])
def test_on_a_terminal_the_message_wraps_at_words_never_the_location(
    monkeypatch: pytest.MonkeyPatch, width: int
) -> None:
    monkeypatch.setenv("COLUMNS", str(width))
    monkeypatch.setenv("NO_COLOR", "1")
    stream = Terminal()
    report = Report((FileResult("shot.usda", findings=(LONG, DEEP)),))
    TextFormatter().render(report, stream, FormatOptions())
    lines = stream.getvalue().splitlines()
    starts = [i for i, line in enumerate(lines) if not line.startswith(INDENT)]
    assert [lines[i].split(" ")[0] for i in starts[:2]] == [
        DEEP.location.layer + ":7:",  # longer than the line: kept whole, never cut
        "shots/010/shot.usda:32:",
    ]
    for index, line in enumerate(lines):
        if index in starts[:2] and len(line.split(" ")[0]) > width:
            assert line.count(" ") <= 3  # the location, severity, code and path alone
        else:
            assert len(line) <= width, line
    # Nothing lost: the wrapped words are the message's words.
    first = " ".join(lines[starts[1] : starts[2]]).split()
    assert (
        first
        == (
            f"shots/010/shot.usda:32: error CA004 /Render/PrimarySettings.camera: {LONG.message}"
            " [fix: retarget camera to </World/camRig/shotCam>]"
        ).split()
    )


def test_on_a_terminal_the_summary_never_cuts_an_option_at_its_hyphens(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``--unsafe-fixes`` wraps whole, as the findings' words do: cut after
    ``--unsafe-`` it could not be copied back into a command."""
    monkeypatch.setenv("NO_COLOR", "1")
    unsafe = Finding(
        "SE003",
        "data-window-malformed",
        Severity.ERROR,
        "dataWindowNDC is inverted",
        Location("s.usda", "/R/S.dataWindowNDC", "s.usda", 7),
        FixInfo("swap xmin and xmax", False),
    )
    report = Report((FileResult("s.usda", findings=(LONG, unsafe)),))
    for width in range(40, 120):
        monkeypatch.setenv("COLUMNS", str(width))
        stream = Terminal()
        TextFormatter().render(report, stream, FormatOptions())
        summary = stream.getvalue().split("]\n")[-1]
        assert "--unsafe-fixes" in " ".join(summary.split()), (width, summary)


def test_wide_characters_wrap_at_the_terminals_columns(monkeypatch: pytest.MonkeyPatch) -> None:
    # A CJK character takes two columns: a line of them wraps at half as many.
    monkeypatch.setenv("COLUMNS", "40")
    monkeypatch.setenv("NO_COLOR", "1")
    wide = Finding(
        "SE012",
        "rendering-color-space-unknown",
        Severity.WARNING,
        " ".join(["色空間"] * 12),
        Location("s.usda", "/R", "s.usda", 3),
    )
    stream = Terminal()
    TextFormatter().render(
        Report((FileResult("s.usda", findings=(wide,)),)), stream, FormatOptions()
    )
    for line in stream.getvalue().splitlines()[:-1]:
        assert len(line) + sum(char == "色" or char == "空" or char == "間" for char in line) <= 40


def test_piped_lines_are_never_wrapped() -> None:
    stream = io.StringIO()
    TextFormatter().render(
        Report((FileResult("shot.usda", findings=(LONG,)),)), stream, FormatOptions()
    )
    assert len(stream.getvalue().splitlines()) == 2  # the finding and the summary


def test_colours_on_a_terminal_and_no_style_at_all_with_no_color(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    report = Report((FileResult("shot.usda", findings=(LONG,)),))
    monkeypatch.delenv("NO_COLOR", raising=False)
    monkeypatch.setenv("TERM", "xterm-256color")
    coloured = Terminal()
    TextFormatter().render(report, coloured, FormatOptions())
    assert "\x1b[1;31merror\x1b[0m" in coloured.getvalue()  # severity colour
    assert "\x1b[2m[fix:" in coloured.getvalue()  # the fix hint is dim
    monkeypatch.setenv("NO_COLOR", "1")
    plain = Terminal()
    TextFormatter().render(report, plain, FormatOptions())
    assert "\x1b" not in plain.getvalue()
    assert plain.getvalue().split() == re.sub(r"\x1b\[[\d;]*m", "", coloured.getvalue()).split()
    monkeypatch.setenv("NO_COLOR", "")  # an empty NO_COLOR does not count (no-color.org)
    empty = Terminal()
    TextFormatter().render(report, empty, FormatOptions())
    assert "\x1b[" in empty.getvalue()


def test_the_summary_counts_what_fix_and_unsafe_fixes_would_fix(shot: Path) -> None:
    result = check("--select", "SE002,SE003,SE009", "shots/shot.usda")
    # SE009 (repeated purpose) has a safe fix, SE003 (inverted window) an unsafe one,
    # SE002 none.
    assert result.stdout.splitlines()[-1] == (
        "3 findings in 1 file: 2 errors, 1 warning, 0 info; 1 fixable with --fix"
        " (1 more with --unsafe-fixes)."
    )
    unsafe_only = check("--select", "SE002,SE003", "shots/shot.usda")
    assert unsafe_only.stdout.splitlines()[-1].endswith("; 1 fixable with --fix --unsafe-fixes.")
    none = check("--select", "SE002", "shots/shot.usda")
    assert "fixable" not in none.output


def test_the_summary_leaves_out_the_fixes_of_unfixable_rules(shot: Path) -> None:
    (shot / ".usdrender-lint.toml").write_text(
        'select = ["SE003", "SE009"]\nunfixable = ["SE009"]\n'
    )
    result = CliRunner().invoke(cli, ["check", "--jobs", "1", "shots/shot.usda"])
    assert result.stdout.splitlines()[-1].endswith("; 1 fixable with --fix --unsafe-fixes.")


def test_the_summary_counts_no_fix_under_config_variants(shot: Path) -> None:
    # It said "2 fixable with --fix" where check --fix refuses the configuration.
    (shot / ".usdrender-lint.toml").write_text('select = ["SE003", "SE009"]\nvariants = true\n')
    result = CliRunner().invoke(cli, ["check", "--jobs", "1", "shots/shot.usda"])
    assert "SE009" in result.stdout
    assert "fixable" not in result.stdout.splitlines()[-1]
    fix = CliRunner().invoke(cli, ["check", "--jobs", "1", "--fix", "shots/shot.usda"])
    assert fix.exit_code == 2 and "variants" in fix.stderr


def test_no_format_offers_a_fix_under_config_variants(shot: Path) -> None:
    # The summary counted none, as check --fix refuses the configuration, while
    # each line said "[fix: ...]" and JSON, JUnit and HTML (with its diff) offered it.
    (shot / ".usdrender-lint.toml").write_text('select = ["SE003", "SE009"]\nvariants = true\n')
    base = ["check", "--jobs", "1", "--no-cache", "shots/shot.usda"]
    text = CliRunner().invoke(cli, base).stdout
    assert "SE009" in text and "fix" not in text
    document = json.loads(CliRunner().invoke(cli, [*base, "--format", "json"]).stdout)
    fixes = [f["fix"] for e in document["files"] for f in e["findings"]]
    assert fixes and fixes == [None] * len(fixes)
    for fmt, offered in (("junit", "fix: "), ("html", 'class="fix"')):
        assert offered not in CliRunner().invoke(cli, [*base, "--format", fmt]).stdout, fmt


def test_a_finding_of_an_unfixable_rule_offers_no_fix(shot: Path) -> None:
    # Its line said "[fix: ...]" as any other, while --fix leaves it alone and
    # the summary did not count it. Now it offers none, as every other format
    # (tests/formatters/test_unfixable_routes.py) and ruff.
    (shot / ".usdrender-lint.toml").write_text('select = ["SE009"]\nunfixable = ["SE009"]\n')
    result = CliRunner().invoke(cli, ["check", "--jobs", "1", "shots/shot.usda"])
    [line] = [line for line in result.stdout.splitlines() if " SE009 " in line]
    assert "fix" not in line


def test_the_problem_matcher_reads_the_text_report(shot: Path) -> None:
    """examples/usdrender-lint-problem-matcher.json against real report lines
    (the Actions runner's regular expressions are .NET's; this one uses only
    what Python's share with them)."""
    [matcher] = json.loads(MATCHER.read_text())["problemMatcher"]
    [pattern] = matcher["pattern"]
    regexp = re.compile(pattern["regexp"])
    group = {key: pattern[key] for key in ("file", "line", "column", "severity", "code", "message")}
    (shot / "gone.usda").symlink_to(shot / "nowhere.usda")
    result = check("--select", "SE003,SE009,ST001", "shots", "gone.usda")
    lines = result.stdout.splitlines()
    found = []
    for line in lines[:-1]:
        match = regexp.match(line)
        assert match, line
        found.append({key: match.group(index) for key, index in group.items()})
    assert regexp.match(lines[-1]) is None  # the summary is not a problem
    assert found[0] == {
        "file": "gone.usda",
        "line": None,
        "column": None,
        "severity": "error",
        "code": None,
        "message": "a broken or looping symbolic link",
    }
    assert found[1]["file"] == "shots/broken.usda"
    assert (found[1]["line"], found[1]["column"], found[1]["code"]) == ("5", "1", "ST001")
    assert found[2] == {
        "file": "shots/lighting.usda",
        "line": "6",
        "column": None,
        "severity": "error",
        "code": "SE003",
        "message": found[2]["message"],
    }
    assert found[2]["message"].startswith("/Render/Settings.dataWindowNDC: dataWindowNDC (1, 1,")
    assert (found[3]["severity"], found[3]["code"]) == ("warning", "SE009")
