"""The stable machine format: one JSON document on stdout (schema_version 1),
written with the report codec (:mod:`usdrender_lint.report_json`)."""

from __future__ import annotations

from typing import Any, TextIO

from ..model import Report
from ..report_json import report_to_dict as document_of
from . import FormatOptions, json_text, statistics


def report_to_dict(report: Report, options: FormatOptions) -> dict[str, Any]:
    return document_of(
        report,
        options.tool_name,
        options.tool_version,
        with_fixes=options.fixing,
        statistics=statistics(report) if options.statistics else None,
        configuration=options.configuration,
        shard=options.shard,
    )


class JsonFormatter:
    #: It never reads Report.rules, so the command does not build them.
    reads_rules = False

    def render(self, report: Report, stream: TextIO, options: FormatOptions) -> None:
        stream.write(json_text(report_to_dict(report, options)))
