"""Messages that forge output (issue 31, item 5): control characters in token
values and file names are escaped in the text, GitHub and SARIF reports (a layer
could forge report lines or send terminal escape codes), every printed message
has a length bound, and the JSON report keeps the whole text."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.formatters import FormatOptions, load_formatter
from usdrender_lint.model import FileResult, Finding, Location, Report, Severity
from usdrender_lint.paths import PRINT_LIMIT, printable

# SE006 and SE012 quote the token values; the first forges a report line and
# retitles the terminal, the second colours and reverses what follows.
FORGING = r"""#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform token aspectRatioConformPolicy = "x\x1b]0;pwned\x07\nforged.usda:1: error SE9: fake"
        token renderingColorSpace = "lin\x1b[31m\x7f"
    }
}
"""
CONTROLS = ("\x1b", "\x07", "\x7f")


def _render(report: Report, fmt: str) -> str:
    stream = io.StringIO()
    load_formatter(fmt).render(report, stream, FormatOptions(show_info=True))
    return stream.getvalue()


def test_printable_escapes_controls_and_bounds_length() -> None:
    assert printable("a\x1b[2Jb\nc\td\x9b\u202ee") == "a\\x1b[2Jb\\nc\\td\\x9b\\u202ee"
    assert printable("a\r\nb", keep="\r\n") == "a\r\nb"
    assert printable("plain text, é and 日本") == "plain text, é and 日本"
    long = printable("x" * 200_000)
    assert len(long) < PRINT_LIMIT + 100 and long.endswith(
        "... [cut: 200,000 characters in all; the JSON report holds them]"
    )


@pytest.mark.parametrize("fmt", ["text", "github", "sarif"])
def test_token_values_cannot_forge_report_lines(tmp_path: Path, fmt: str) -> None:
    (tmp_path / "shot.usda").write_text(FORGING)
    result = CliRunner().invoke(
        cli,
        [
            "check",
            "--isolated",
            "-j",
            "1",
            "--timeout",
            "0",
            "--format",
            fmt,
            "--select",
            "SE006,SE012",
            str(tmp_path / "shot.usda"),
        ],
    )
    assert result.exit_code == 1, result.output
    assert not any(c in result.stdout for c in CONTROLS), fmt
    lines = result.stdout.splitlines()
    assert not any(line.startswith("forged.usda") for line in lines)
    if fmt != "sarif":
        assert sum("SE006" in line for line in lines) == 1
        assert "x\\x1b]0;pwned\\x07" in result.stdout and "lin\\x1b[31m\\x7f" in result.stdout


def test_the_json_report_keeps_the_raw_text(tmp_path: Path) -> None:
    (tmp_path / "shot.usda").write_text(FORGING)
    result = CliRunner().invoke(
        cli,
        [
            "check",
            "--isolated",
            "-j",
            "1",
            "--timeout",
            "0",
            "--format",
            "json",
            "--select",
            "SE006",
            str(tmp_path / "shot.usda"),
        ],
    )
    message = json.loads(result.stdout)["files"][0]["findings"][0]["message"]
    assert "x\x1b]0;pwned\x07\nforged.usda:1: error SE9: fake" in message


def _named(name: str, message: str = "bad") -> Report:
    finding = Finding(
        "ST001", "stage-open-failed", Severity.ERROR, message, Location(name, None, name, 1)
    )
    return Report(
        (
            FileResult(name, "linted", None, (finding,)),
            FileResult(name + "2", "error", f"{name}2: {message}", ()),
        )
    )


@pytest.mark.parametrize("fmt", ["text", "github", "sarif"])
def test_file_names_with_controls_are_escaped(fmt: str) -> None:
    out = _render(_named("shot\x1b[2J\nfake.usda"), fmt)
    assert "\x1b" not in out
    assert not any(line.startswith("fake.usda") for line in out.splitlines())


@pytest.mark.parametrize("fmt", ["text", "github", "sarif"])
def test_a_huge_message_is_cut_where_it_is_printed_and_whole_in_json(fmt: str) -> None:
    """An ST001 message was printed whole: 198,947 characters on one line."""
    huge = "USD said: " + "y" * 200_000
    out = _render(_named("shot.usda", huge), fmt)
    assert len(out) < 4 * PRINT_LIMIT + 4000
    assert "characters in all; the JSON report holds them]" in out
    document = json.loads(_render(_named("shot.usda", huge), "json"))
    assert document["files"][0]["findings"][0]["message"] == huge
