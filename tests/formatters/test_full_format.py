"""``--format full``: the text report, each finding's source line under it with
the statement marked. Without the source blocks it is the text report line
for line; each block shows the layer's own line, the marks under its statement."""

from __future__ import annotations

import io
import json
import os
import re
from pathlib import Path

import pytest
from click.testing import CliRunner
from pxr import Sdf

from usdrender_lint.cli import cli
from usdrender_lint.formatters import FormatOptions
from usdrender_lint.formatters.full import PIPED_COLUMNS, FullFormatter
from usdrender_lint.model import FileResult, Finding, Location, Report, Severity

pytestmark = pytest.mark.heavy(seconds=13)

REPO = Path(__file__).resolve().parents[2]
#: Every rule fixture and example: findings in sublayers and references, parse
#: errors with columns, crates (none here, one below), many rules.
FILES = sorted(
    str(p.relative_to(REPO))
    for p in [*(REPO / "tests" / "rules").rglob("*.usda"), *(REPO / "examples").rglob("*.usd*")]
    if not p.name.endswith(".fixed.usda")
)
#: A source block: the gutter, the numbered line, the marks, a blank line.
BLOCK = re.compile(
    r"^(?P<gutter> *) \|\n(?P<number>\d+) \| (?P<content>.*)\n"
    r"(?P=gutter) \| (?P<spaces> *)(?P<marks>\^+)\n\n",
    re.MULTILINE,
)
#: A finding's line (piped: one line) and its block.
HEAD_AND_BLOCK = re.compile(
    r"^(?P<path>\S+?):(?P<line>\d+)(?::(?P<column>\d+))?: .*\n" + BLOCK.pattern[1:], re.MULTILINE
)


def _check(fmt: str, *paths: str, cwd: Path = REPO) -> str:
    previous = os.getcwd()
    os.chdir(cwd)
    try:
        result = CliRunner().invoke(
            cli, ["check", "--no-cache", "--jobs", "1", "--show-info", "--format", fmt, *paths]
        )
    finally:
        os.chdir(previous)
    assert result.exit_code in (0, 1, 2), result.output
    return result.stdout


@pytest.fixture(scope="module")
def full() -> str:
    """The full report of every rule fixture and example: one lint of them (about
    a thousand files) for the tests that read it."""
    return _check("full", *FILES)


def test_without_its_source_blocks_full_is_the_text_report(full: str) -> None:
    assert BLOCK.search(full)
    assert BLOCK.sub("", full) == _check("text", *FILES)


def test_each_block_is_the_layers_line_with_its_statement_marked(full: str) -> None:
    shown = 0
    for match in HEAD_AND_BLOCK.finditer(full):
        path, line = match["path"], int(match["line"])
        assert match["number"] == match["line"]
        source = (REPO / path).read_text(encoding="utf-8").split("\n")[line - 1]
        expected = source.expandtabs(4)
        content, spaces, marks = match["content"], match["spaces"], match["marks"]
        assert content == expected, (path, line)
        if match["column"] is None:  # a statement: marked from its first word
            assert len(spaces) == len(expected) - len(expected.lstrip()), (path, line)
            assert expected[len(spaces) :].rstrip().startswith(expected.strip()[: len(marks)])
        else:  # a parse error: from USD's column
            assert len(spaces) == int(match["column"]) - 1, (path, line)
        shown += 1
    # Most findings sit on a text layer's line (a few name no line: a missing file, ST003).
    assert shown > 300


def _report(path: Path, line: int, column: int | None = None) -> Report:
    finding = Finding(
        "SE003",
        "data-window-malformed",
        Severity.ERROR,
        "inverted",
        Location(str(path), "/R.dataWindowNDC", str(path), line, column),
    )
    return Report((FileResult(str(path), findings=(finding,)),))


def _render(report: Report, stream: io.StringIO | None = None) -> list[str]:
    stream = stream or io.StringIO()
    FullFormatter().render(report, stream, FormatOptions())
    return stream.getvalue().split("\n")


def test_tabs_and_control_characters_keep_the_marks_under_the_statement(tmp_path: Path) -> None:
    layer = tmp_path / "tabs.usda"
    layer.write_text("#usda 1.0\n\t\tuniform float4 dataWindowNDC = (1, 0, 0, 1) # \x0c\x01\n")
    lines = _render(_report(layer, 2))
    assert lines[2] == "2 |         uniform float4 dataWindowNDC = (1, 0, 0, 1) # \ufffd\ufffd"
    assert lines[3] == "  |         " + "^" * len(
        "uniform float4 dataWindowNDC = (1, 0, 0, 1) # ??"
    )
    # A column (USD's parse errors) counts a tab as one character, shown as four.
    lines = _render(_report(layer, 2, column=4))
    assert lines[3] == "  | " + " " * 9 + "^" * len(
        "niform float4 dataWindowNDC = (1, 0, 0, 1) # ??"
    )


def test_wide_and_combining_characters_keep_the_marks_under_the_statement(
    tmp_path: Path,
) -> None:
    # A terminal gives a CJK character two columns and a combining mark none.
    layer = tmp_path / "wide.usda"
    statement = 'uniform token renderingColorSpace = "色空間e\u0301"'
    layer.write_text(f"#usda 1.0\n    {statement}\n", encoding="utf-8")
    lines = _render(_report(layer, 2))
    assert lines[2] == f"2 |     {statement}"
    assert lines[3] == "  |     " + "^" * (len(statement) + 3 - 1)
    # Cut at the columns a terminal has, not at as many characters.
    layer.write_text(f"#usda 1.0\n    {statement} # {'字' * 200}\n", encoding="utf-8")
    [source, marks] = _render(_report(layer, 2))[2:4]
    shown = source.removeprefix("2 | ")
    columns = len(shown) + shown.count("字") + 3 - 1  # the statement's three wide, one none
    assert shown.endswith("…") and columns in (PIPED_COLUMNS - 4, PIPED_COLUMNS - 5)
    # The marks run to the cut, under the statement and its comment.
    assert marks == "  | " + "    " + "^" * (columns - 4 - 1)


def test_a_long_line_is_cut_piped_and_at_the_terminals_width(tmp_path: Path, monkeypatch) -> None:
    layer = tmp_path / "long.usda"
    layer.write_text("#usda 1.0\n    uniform float4 dataWindowNDC = (1," + " " * 500 + "0, 0, 1)\n")
    lines = _render(_report(layer, 2))
    assert len(lines[2]) == len("2 | ") + PIPED_COLUMNS - 4 and lines[2].endswith("…")
    assert len(lines[3]) <= len(lines[2]) - 1 and lines[3].endswith("^")

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    monkeypatch.setenv("NO_COLOR", "1")
    monkeypatch.setenv("COLUMNS", "60")
    lines = _render(_report(layer, 2), Terminal())
    block = [line for line in lines if line.startswith(("  |", "2 |"))]
    assert len(block) == 3 and max(len(line) for line in block) <= 60
    [source] = [line for line in lines if line.startswith("2 | ")]
    assert source.endswith("…") and len(source) == 60


def test_a_crate_a_missing_file_and_a_line_past_the_end_show_no_block(tmp_path: Path) -> None:
    crate = tmp_path / "shot.usdc"
    layer = Sdf.Layer.CreateNew(str(crate))
    layer.ImportFromString('#usda 1.0\ndef RenderSettings "S"\n{\n}\n')
    layer.Save()
    short = tmp_path / "short.usda"
    short.write_text("#usda 1.0\n")
    for path, line in ((crate, 2), (tmp_path / "gone.usda", 2), (short, 40)):
        lines = _render(_report(path, line))
        assert len(lines) == 3 and "|" not in "".join(lines), lines  # head, summary, ""


@pytest.mark.parametrize("where", ["here", "elsewhere"])
def test_merge_shows_blocks_where_the_files_are(tmp_path: Path, where: str) -> None:
    report = tmp_path / "report.json"
    broken = REPO / "examples" / "broken_shot"
    report.write_text(_check("json", "shot.usda", cwd=broken))
    cwd = broken if where == "here" else tmp_path
    previous = os.getcwd()
    os.chdir(cwd)
    try:
        merged = CliRunner().invoke(cli, ["merge", "--format", "full", str(report)])
    finally:
        os.chdir(previous)
    assert merged.exit_code == 1, merged.output
    assert bool(BLOCK.search(merged.stdout)) == (where == "here")
    assert json.loads(report.read_text())["summary"]["findings"] == 5
