"""The human format: findings grouped per file, severity coloured (rich)."""

from __future__ import annotations

from typing import TextIO

from rich.console import Console
from rich.markup import escape

from ..model import Report, Severity
from . import FormatOptions, display_path, statistics_lines

_STYLE = {Severity.ERROR: "bold red", Severity.WARNING: "yellow", Severity.INFO: "cyan"}


def _plural(count: int, word: str, plural: str | None = None) -> str:
    return f"{count} {word}" if count == 1 else f"{count} {plural or word + 's'}"


class TextFormatter:
    def render(self, report: Report, stream: TextIO, options: FormatOptions) -> None:
        # rich drops colour by itself when the stream is no terminal or NO_COLOR is set.
        console = Console(file=stream, soft_wrap=True, highlight=False)
        hidden = 0
        for result in report.files:
            shown = [f for f in result.findings if options.show_info or f.severity != Severity.INFO]
            hidden += len(result.findings) - len(shown)
            if result.status != "linted":
                console.print(f"[bold]{escape(result.file)}[/]")
                console.print(f"  [bold red]error[/]  {escape(result.error or 'failed')}")
                continue
            if not shown:
                continue
            console.print(f"[bold]{escape(result.file)}[/]")
            for finding in shown:
                loc = finding.location
                where = display_path(loc.layer) if loc.layer else ""
                if where and loc.line:
                    where += f":{loc.line}"
                style = _STYLE[finding.severity]
                parts = [
                    f"  [{style}]{finding.severity.value:<7}[/]",
                    f"[bold]{finding.code}[/]",
                    escape(loc.path or "(file)"),
                    escape(finding.message),
                ]
                if where:
                    parts.append(f"[dim]({escape(where)})[/]")
                if finding.fix is not None:
                    kind = "fix" if finding.fix.safe else "unsafe fix"
                    parts.append(f"[dim]{escape(f'[{kind}: {finding.fix.description}]')}[/]")
                console.print("  ".join(parts))
        for fix in report.applied_fixes:
            where = f"  [dim]({escape(display_path(fix.layer))})[/]" if fix.layer else ""
            parts = [fix.code, fix.path or "(file)", fix.description]
            console.print(f"  [green]fixed[/]    {escape('  '.join(parts))}{where}")
        console.print(self._summary(report, hidden))
        if options.statistics:
            for line in statistics_lines(report):
                console.print(escape(line))

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
