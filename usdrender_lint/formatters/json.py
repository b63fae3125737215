"""The stable machine format: one JSON document on stdout (schema_version 1)."""

from __future__ import annotations

import json
from typing import Any, TextIO

from ..model import AppliedFix, Finding, Report
from ..paths import display_path
from . import FormatOptions, statistics

SCHEMA_VERSION = 1


def finding_to_dict(finding: Finding) -> dict[str, Any]:
    loc = finding.location
    return {
        "code": finding.code,
        "name": finding.name,
        "severity": finding.severity.value,
        "message": finding.message,
        "path": loc.path,
        "file": loc.file,
        "layer": display_path(loc.layer) if loc.layer else None,
        "line": loc.line,
        "fix": (
            None
            if finding.fix is None
            else {"description": finding.fix.description, "safe": finding.fix.safe}
        ),
        # The renderer profile the finding was judged under, and why (R2-5).
        "profile": finding.profile,
        "profile_reason": finding.profile_reason,
    }


def fix_to_dict(fix: AppliedFix) -> dict[str, Any]:
    return {
        "file": fix.file,
        "code": fix.code,
        "path": fix.path,
        "layer": display_path(fix.layer) if fix.layer else None,
        "description": fix.description,
        "applied": fix.applied,
        "reason": fix.reason,
    }


def report_to_dict(report: Report, options: FormatOptions) -> dict[str, Any]:
    document = _report_to_dict(report, options)
    if options.statistics:
        # Added only with --statistics, so the default document stays as documented.
        document["statistics"] = statistics(report)
    if options.fixing or report.applied_fixes or report.unapplied_fixes:
        # Added only when fixing, like "statistics".
        document["fixes"] = [
            fix_to_dict(fix) for fix in (*report.applied_fixes, *report.unapplied_fixes)
        ]
    return document


def _report_to_dict(report: Report, options: FormatOptions) -> dict[str, Any]:
    return {
        "schema_version": SCHEMA_VERSION,
        "tool": {"name": options.tool_name, "version": options.tool_version},
        "files": [
            {
                "file": result.file,
                "status": result.status,
                "error": result.error,
                "findings": [finding_to_dict(f) for f in result.findings],
            }
            for result in report.files
        ],
        "summary": {
            "files": len(report.files),
            "findings": len(report.findings),
            "by_severity": report.by_severity(),
        },
    }


class JsonFormatter:
    #: It never reads Report.rules, so the command does not build them.
    reads_rules = False

    def render(self, report: Report, stream: TextIO, options: FormatOptions) -> None:
        json.dump(report_to_dict(report, options), stream, indent=2, ensure_ascii=False)
        stream.write("\n")
