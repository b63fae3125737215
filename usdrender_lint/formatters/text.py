"""The human format: findings grouped per file, severity coloured.

rich renders it on a terminal; piped output is the same text written plainly,
so a CI log or a pipe pays neither rich's import nor its escapes.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from typing import TextIO

from ..model import Report, Severity
from ..paths import display_path
from . import FormatOptions, statistics_lines

_STYLE = {Severity.ERROR: "bold red", Severity.WARNING: "yellow", Severity.INFO: "cyan"}

#: A line is a list of (text, rich style or None) segments.
Line = list[tuple[str, str | None]]


def _plural(count: int, word: str, plural: str | None = None) -> str:
    return f"{count} {word}" if count == 1 else f"{count} {plural or word + 's'}"


def _is_terminal(stream: TextIO) -> bool:
    isatty = getattr(stream, "isatty", None)
    return bool(isatty and isatty())


def write_lines(lines: Iterable[Line], stream: TextIO) -> None:
    """Styled lines through rich on a terminal; plain text otherwise."""
    if not _is_terminal(stream):
        for line in lines:
            stream.write("".join(text for text, _ in line) + "\n")
        return
    from rich.console import Console
    from rich.markup import escape

    # rich drops colour by itself when NO_COLOR is set.
    console = Console(file=stream, soft_wrap=True, highlight=False)
    for line in lines:
        console.print("".join(f"[{s}]{escape(t)}[/]" if s else escape(t) for t, s in line))


class TextFormatter:
    #: It never reads Report.rules, so the command does not build them.
    reads_rules = False

    def render(self, report: Report, stream: TextIO, options: FormatOptions) -> None:
        write_lines(self._lines(report, options), stream)

    def _lines(self, report: Report, options: FormatOptions) -> Iterator[Line]:
        hidden = 0
        for result in report.files:
            shown = [f for f in result.findings if options.show_info or f.severity != Severity.INFO]
            hidden += len(result.findings) - len(shown)
            if result.status != "linted":
                yield [(result.file, "bold")]
                yield [
                    ("  ", None),
                    ("error", "bold red"),
                    ("  " + (result.error or "failed"), None),
                ]
                continue
            if not shown:
                continue
            yield [(result.file, "bold")]
            for finding in shown:
                loc = finding.location
                where = display_path(loc.layer) if loc.layer else ""
                if where and loc.line:
                    where += f":{loc.line}"
                line: Line = [
                    ("  ", None),
                    (f"{finding.severity.value:<7}", _STYLE[finding.severity]),
                    ("  ", None),
                    (finding.code, "bold"),
                    (f"  {loc.path or '(file)'}  {finding.message}", None),
                ]
                if where:
                    line.append((f"  ({where})", "dim"))
                if finding.fix is not None:
                    kind = "fix" if finding.fix.safe else "unsafe fix"
                    line.append((f"  [{kind}: {finding.fix.description}]", "dim"))
                if options.show_info and finding.profile:
                    line.append((f"  [profile {finding.profile}: {finding.profile_reason}]", "dim"))
                yield line
        for fix in report.applied_fixes:
            parts = [fix.code, fix.path or "(file)", fix.description]
            line = [("  ", None), ("fixed", "green"), ("    " + "  ".join(parts), None)]
            if fix.layer:
                line.append((f"  ({display_path(fix.layer)})", "dim"))
            yield line
        yield [(self._summary(report, hidden), None)]
        if options.statistics:
            for text in statistics_lines(report):
                yield [(text, None)]

    @staticmethod
    def _summary(report: Report, hidden: int) -> str:
        counts = report.by_severity()
        errors = len(report.errored_files)
        text = (
            f"{_plural(len(report.findings) - hidden, 'finding')} in "
            f"{_plural(len(report.files), 'file')}: "
            f"{_plural(counts['error'], 'error')}, {_plural(counts['warning'], 'warning')}, "
            f"{counts['info']} info"
        )
        if hidden:
            text += f" ({hidden} info hidden; --show-info shows them)"
        if errors:
            text += f"; {_plural(errors, 'file')} could not be linted"
        if report.applied_fixes:
            text += f"; {_plural(len(report.applied_fixes), 'fix', 'fixes')} applied"
        if report.unapplied_fixes:
            text += f"; {_plural(len(report.unapplied_fixes), 'fix', 'fixes')} not applied"
        return text + "."
