"""Report formatters: one protocol, registered through the
``usdrender_lint.formatters`` entry point group like third-party ones."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, Protocol, TextIO

from ..entrypoints import EntryPointLike, entry_points
from ..model import Finding, FixInfo, Report
from ..paths import escape
from ..records import record

ENTRY_POINT_GROUP = "usdrender_lint.formatters"


@record(frozen=True)
class FormatOptions:
    show_info: bool = False
    tool_name: str = "usdrender-lint"
    tool_version: str = "0"
    #: Add counts per rule code after the report (--statistics).
    statistics: bool = False
    #: The findings and nothing else (--quiet): no summary line, no fixes applied.
    quiet: bool = False
    #: Fixing was asked for (--fix, --diff, --fix-to): report the fixes.
    fixing: bool = False
    #: --diff: the fixes were computed and written nowhere, so the report says
    #: what would be applied, never that it was.
    dry_run: bool = False
    #: The run's configuration digest (running/merge.py), for the JSON report.
    configuration: str | None = None
    #: The (K, N) of check --shard K/N, recorded in the JSON report for merge.
    shard: tuple[int, int] | None = None
    #: The configuration (config.Settings) each file was linted with, for a formatter
    #: that reads the files again (html's pictures and fix diffs); None for a file,
    #: or no function: the file's nearest configuration.
    settings_of: Callable[[str], Any] | None = None


#: What a report for people says beside a fix the baseline holds back (Report.baseline_held).
HELD_BY_BASELINE = "not applied while the baseline records this rule here"


def shown_fix(report: Report, finding: Finding) -> tuple[FixInfo, bool] | None:
    """The fix a report for people shows under ``finding``, and whether it is
    one the baseline holds back, shown marked (HELD_BY_BASELINE) as --fix
    leaves it. Whether a fix is offered is Report.offered_fix's answer, which
    the machine formats write and every summary counts."""
    offered = report.offered_fix(finding)
    if offered is not None:
        return offered, False
    if finding.fix is not None and finding in report.baseline_held:
        return finding.fix, True
    return None


class Formatter(Protocol):
    def render(self, report: Report, stream: TextIO, options: FormatOptions) -> None:
        """Write the whole report to ``stream``."""


def reads_rules(formatter: Formatter) -> bool:
    """Whether ``formatter`` reads ``Report.rules`` (the rules' docs). One that
    never does says so with ``reads_rules = False`` and is handed none; one
    that says nothing gets them."""
    return bool(getattr(formatter, "reads_rules", True))


def reads_configuration(formatter: Formatter) -> bool:
    """Whether ``formatter`` reads ``FormatOptions.configuration`` (the run's
    digest, which costs hashlib and json to compute): as for the rules, one
    that never does says so with ``reads_configuration = False``."""
    return bool(getattr(formatter, "reads_configuration", True))


def available_formatters() -> Mapping[str, EntryPointLike]:
    return {ep.name: ep for ep in entry_points(ENTRY_POINT_GROUP)}


def load_formatter(name: str, available: Mapping[str, EntryPointLike] | None = None) -> Formatter:
    """Import only the chosen formatter (rich is loaded only for text).
    ``available``: what :func:`available_formatters` answered a moment ago (the
    command line's --format was checked against it), not asked again."""
    entry_points = available_formatters() if available is None else available
    if name not in entry_points:
        raise KeyError(name)
    return entry_points[name].load()()


def statistics(report: Report) -> list[dict[str, object]]:
    """Findings per rule code, most frequent first: code, name, severity, count."""
    first: dict[str, Finding] = {}
    for finding in report.findings:
        first.setdefault(finding.code, finding)
    counts = report.by_code()
    return [
        {"code": code, "name": f.name, "severity": f.severity.value, "count": counts[code]}
        for code, f in sorted(first.items(), key=lambda item: (-counts[item[0]], item[0]))
    ]


def statistics_lines(report: Report) -> list[str]:
    """The statistics as plain text lines: count, code, severity, name. The
    severity says which rows are info findings the text report hides, whose
    counts would otherwise not add up to the summary's."""
    return [
        f"{row['count']:>5}  {row['code']}  {row['severity']:<7}  {row['name']}"
        for row in statistics(report)
    ]


def json_text(document: object) -> str:
    """``document`` as indented JSON that is valid UTF-8: a file name that is
    not UTF-8 is written in the lossless form of :func:`usdrender_lint.paths.escape`."""
    import json

    text = json.dumps(document, indent=2, ensure_ascii=False)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        text = json.dumps(escaped(document), indent=2, ensure_ascii=False)
    return text + "\n"


def escaped(value: Any, convert: Callable[[str], str] = escape) -> Any:
    """``value`` (a JSON-like document) with every string, keys included,
    passed through ``convert``: by default the lossless form of a name that is
    not UTF-8; :func:`~usdrender_lint.paths.printable` for a view printed as is."""
    if isinstance(value, str):
        return convert(value)
    if isinstance(value, dict):
        return {escaped(key, convert): escaped(item, convert) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [escaped(item, convert) for item in value]
    return value
