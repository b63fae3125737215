"""GitLab Code Quality report, for ``artifacts: reports: codequality:``.

A JSON array of issues, each with ``description``, ``check_name``,
``fingerprint``, ``severity`` (``info``, ``minor``, ``major``, ``critical`` or
``blocker``), ``location.path`` (relative to the repository root) and
``location.lines.begin``: the subset of the Code Climate issue GitLab reads
(https://docs.gitlab.com/ci/testing/code_quality/, "Code Quality report
format"; Code Climate's issue:
https://github.com/codeclimate/platform/blob/master/spec/analyzers/SPEC.md#issues).

- The path is the layer holding the offending opinion (else the linted file),
  relative to the root of the Git work tree the working directory is in (else
  to the working directory), as GitLab reads it ("a relative path in the
  repository"), so a job run from a subfolder names the files as one run from
  the root; the line is that layer's when known, else 1 (GitLab wants a line;
  a whole-file finding sits at the file's start).
- The fingerprint (:mod:`~usdrender_lint.formatters.fingerprints`, the value
  the SARIF report's ``partialFingerprints`` carry) is a SHA-256 of the rule
  code, the linted file and the layer (both relative), the prim or property
  path and the message, with the occurrence index of an identical finding:
  GitLab shows findings with the same fingerprint as one, and compares a merge
  request's with its target branch's by it. The line is left out, so an edit
  above a finding does not make it new.
- Info findings only with --show-info, as in the text and GitHub reports. A file
  that could not be linted is a ``blocker`` issue under ST001, the code
  ``usdrender-lint`` gives a file no rule could check (running/documents.py).
- --statistics adds nothing: the document is the array of issues and nothing
  else.
"""

from __future__ import annotations

from typing import Any, TextIO

from ..model import FileResult, Finding, Report, Severity
from ..paths import display_path, layer_file, printable, relative_in, repository_root
from . import FormatOptions, json_text
from .fingerprints import Occurrences, fingerprint

#: GitLab lists the five severities and orders findings by them; Code Climate
#: calls them the issue's "potential impact"; neither says more. An error fails
#: the gate by default (--fail-on error): critical. A warning does not: minor,
#: leaving major between them. Blocker, the top, is for a file no rule checked,
#: whose findings are unknown.
SEVERITY = {Severity.ERROR: "critical", Severity.WARNING: "minor", Severity.INFO: "info"}
NOT_LINTED_SEVERITY = "blocker"
#: engine.stage.STAGE_OPEN_FAILED_CODE, not imported: that module loads pxr.
NOT_LINTED_CODE = "ST001"


def _issue(finding: Finding, occurrences: Occurrences) -> dict[str, Any]:
    loc = finding.location
    layer = layer_file(loc.layer)
    path = display_path(str(layer or loc.file), occurrences.base)
    stage = display_path(loc.file, occurrences.base)
    where = f"{loc.path}: " if loc.path else ""
    # The layer may be a sublayer of several stages: say which one.
    seen_from = f" (stage {stage})" if path != stage else ""
    description = f"{finding.code} {where}{finding.message} [{finding.name}]{seen_from}"
    line = loc.line if layer is not None and loc.line else 1
    return {
        # Code Climate wants one line: controls (newlines too) are escaped.
        "description": printable(description),
        "check_name": finding.code,
        "fingerprint": occurrences.fingerprint(finding),
        "severity": SEVERITY[finding.severity],
        "location": {"path": path, "lines": {"begin": line}},
    }


def _not_linted(result: FileResult, occurrences: Occurrences) -> dict[str, Any]:
    path = display_path(result.file, occurrences.base)
    # Relative as the findings' messages are (check.emit_report), for the fingerprint.
    reason = relative_in(result.error or f"{result.file}: could not be linted")
    key = (NOT_LINTED_CODE, path, reason)
    return {
        "description": printable(f"{NOT_LINTED_CODE} could not be linted: {reason}"),
        "check_name": NOT_LINTED_CODE,
        "fingerprint": fingerprint(*key, occurrence=occurrences(key)),
        "severity": NOT_LINTED_SEVERITY,
        "location": {"path": path, "lines": {"begin": 1}},
    }


def report_to_gitlab(report: Report, options: FormatOptions) -> list[dict[str, Any]]:
    # Paths relative to the repository's root, as GitLab reads them.
    occurrences = Occurrences(repository_root())
    issues: list[dict[str, Any]] = []
    for result in report.files:
        if result.status != "linted":
            issues.append(_not_linted(result, occurrences))
        issues.extend(
            _issue(finding, occurrences)
            for finding in result.findings
            if options.show_info or finding.severity != Severity.INFO
        )
    return issues


class GitlabFormatter:
    #: It never reads Report.rules nor the configuration digest, so the
    #: command does not build them.
    reads_rules = False
    reads_configuration = False

    def render(self, report: Report, stream: TextIO, options: FormatOptions) -> None:
        stream.write(json_text(report_to_gitlab(report, options)))
