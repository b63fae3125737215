"""``usdrender-lint merge REPORT...``: the JSON reports of ``check --shard K/N``
jobs (or any JSON reports) as one report, in any format.

A file that several reports hold is kept once (the first report's result). The
files are ordered by path, so the merged report does not depend on which shard
linted what or on the order the reports are given in; fixes are kept in report
order.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..model import AppliedFix, FileResult, Report
from ..report_json import ReportFormatError, read_report


class MergeError(Exception):
    """A report cannot be read; the message names the file."""


def merge_reports(paths: Sequence[str]) -> Report:
    """One report holding every file of the reports at ``paths``."""
    if not paths:
        raise MergeError("merge needs at least one JSON report")
    files: dict[str, FileResult] = {}
    applied: list[AppliedFix] = []
    unapplied: list[AppliedFix] = []
    for path in paths:
        try:
            report = read_report(path)
        except ReportFormatError as exc:
            raise MergeError(str(exc)) from None
        for result in report.files:
            files.setdefault(result.file, result)
        applied.extend(report.applied_fixes)
        unapplied.extend(report.unapplied_fixes)
    return Report(
        tuple(files[name] for name in sorted(files)),
        applied_fixes=tuple(applied),
        unapplied_fixes=tuple(unapplied),
    )


__all__ = ["MergeError", "merge_reports"]
