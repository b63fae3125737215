"""The text report: coloured by rich on a terminal, plain when piped."""

from __future__ import annotations

import io
import re
import sys

import pytest

from usdrender_lint.formatters import FormatOptions
from usdrender_lint.formatters.text import TextFormatter
from usdrender_lint.model import FileResult, Finding, FixInfo, Location, Report, Severity

REPORT = Report(
    (
        FileResult(
            "shot.usda",
            findings=(
                Finding(
                    "CA004",
                    "camera-target-not-camera",
                    Severity.ERROR,
                    "camera target </rig> is an Xform [not a Camera]",
                    Location("shot.usda", "/Render/S.camera", None, None),
                    FixInfo("retarget", True),
                ),
                Finding(
                    "ST003",
                    "render-settings-path-missing",
                    Severity.INFO,
                    "no path",
                    Location("shot.usda", None, None, None),
                ),
            ),
        ),
        FileResult("gone.usda", status="error", error="gone.usda: no such file"),
    )
)


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_piped_output_is_plain_and_does_not_import_rich(monkeypatch) -> None:
    for name in [m for m in sys.modules if m == "rich" or m.startswith("rich.")]:
        monkeypatch.delitem(sys.modules, name)
    stream = io.StringIO()
    TextFormatter().render(REPORT, stream, FormatOptions())
    assert "rich" not in sys.modules
    assert stream.getvalue().splitlines() == [
        "gone.usda: error: no such file",
        "shot.usda: error CA004 /Render/S.camera: camera target </rig> is an Xform"
        " [not a Camera] [fix: retarget]",
        "1 finding in 2 files: 1 error, 0 warnings (1 info hidden; --show-info shows"
        " them); 1 file could not be linted; 1 fixable with --fix.",
    ]


def test_terminal_output_is_coloured_with_the_same_text(monkeypatch) -> None:
    monkeypatch.delenv("NO_COLOR", raising=False)
    monkeypatch.setenv("TERM", "xterm-256color")
    stream = Terminal()
    TextFormatter().render(REPORT, stream, FormatOptions(show_info=True))
    text = stream.getvalue()
    assert "\x1b[" in text
    assert "[not a Camera]" in " ".join(text.split())  # markup-like text is escaped, not eaten
    assert "ST003" in text


def test_no_color_on_a_terminal(monkeypatch) -> None:
    monkeypatch.setenv("NO_COLOR", "1")
    stream = Terminal()
    TextFormatter().render(REPORT, stream, FormatOptions())
    # Not even bold or dim (https://no-color.org).
    assert "\x1b[" not in stream.getvalue() and "CA004" in stream.getvalue()


@pytest.mark.parametrize("variable", ["FORCE_COLOR", "CLICOLOR_FORCE"])
def test_forced_colour_colours_a_pipe_without_wrapping(monkeypatch, variable: str) -> None:
    # A CI log is a pipe: ruff and eslint colour it under FORCE_COLOR / CLICOLOR_FORCE.
    for name in ("NO_COLOR", "FORCE_COLOR", "CLICOLOR_FORCE"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("TERM", "xterm-256color")
    monkeypatch.setenv(variable, "1")
    piped = io.StringIO()
    TextFormatter().render(REPORT, piped, FormatOptions())
    assert "\x1b[" in piped.getvalue()
    plain = io.StringIO()
    monkeypatch.setenv("NO_COLOR", "1")  # NO_COLOR wins
    TextFormatter().render(REPORT, plain, FormatOptions())
    assert "\x1b[" not in plain.getvalue()
    assert re.sub(r"\x1b\[[0-9;]*m", "", piped.getvalue()) == plain.getvalue()


def test_the_fixable_count_says_how_many_are_hidden_info_findings() -> None:
    import dataclasses

    (shot, gone) = REPORT.files
    info = dataclasses.replace(shot.findings[1], fix=FixInfo("author it", True))
    unsafe_info = dataclasses.replace(info, code="ST004", fix=FixInfo("guess", False))
    report = Report((dataclasses.replace(shot, findings=(shot.findings[0], info, unsafe_info)),))
    hidden, shown = io.StringIO(), io.StringIO()
    TextFormatter().render(report, hidden, FormatOptions())
    TextFormatter().render(report, shown, FormatOptions(show_info=True))
    assert hidden.getvalue().splitlines()[-1] == (
        "1 finding in 1 file: 1 error, 0 warnings (2 info hidden; --show-info shows them); "
        "2 fixable with --fix, 1 of them hidden info (1 more with --unsafe-fixes)."
    )
    assert shown.getvalue().splitlines()[-1] == (
        "3 findings in 1 file: 1 error, 0 warnings, 2 info; "
        "2 fixable with --fix (1 more with --unsafe-fixes)."
    )


def test_statistics_say_which_counts_are_hidden_info() -> None:
    # The summary counts 1 finding (the info one is hidden) while the table
    # counts both: each row's severity tells the reader why.
    stream = io.StringIO()
    TextFormatter().render(REPORT, stream, FormatOptions(statistics=True))
    lines = stream.getvalue().splitlines()
    assert lines[-3].startswith("1 finding in 2 files")
    assert [line.split() for line in lines[-2:]] == [
        ["1", "CA004", "error", "camera-target-not-camera"],
        ["1", "ST003", "info", "render-settings-path-missing"],
    ]
