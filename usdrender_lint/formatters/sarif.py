"""SARIF 2.1.0 (OASIS), for code-scanning uploads.

Each rule that ran is a ``reportingDescriptor`` with its docstring as help.
A result's physical location is the layer holding the offending opinion (else
the linted file) with its line when known (else line 1: code scanning
requires a line), as a URI relative to the root of the Git work tree the
working directory is in, else to the working directory (``uriBaseId``
SRCROOT, which ``originalUriBaseIds`` names); its logical location is the prim
or property path. Code scanning reads a relative URI as relative to the
repository's root whatever its ``uriBaseId`` ("SARIF support for code
scanning", "Source file locations":
https://docs.github.com/en/code-security/reference/code-scanning/sarif-files/sarif-support),
so a run from a subfolder of the checkout names the files as one from its root.

Info findings (level ``note``) only with --show-info, as in the text, GitHub,
GitLab and JUnit reports: code scanning shows every result as an alert, a
``note`` too, so a finding the text report hides would otherwise be an alert
on every upload. ESLint's --quiet leaves warnings out of every format, SARIF
included (``lib/cli.js``, https://github.com/eslint/eslint/blob/main/lib/cli.js);
SARIF's "all results detected by the tool" (2.1.0 §3.14.23) are those the
options ask for, as with --select. The rules that ran are all described.

Each result carries ``partialFingerprints`` {FINGERPRINT_KEY: the finding's
fingerprint} (:mod:`~usdrender_lint.formatters.fingerprints`, the GitLab
report's): code scanning matches results across commits and branches by their
fingerprints, and an upload without them (the REST API, or another uploader
than ``upload-sarif``, which computes a line hash only for text files) shows a
moved finding as a new alert ("SARIF support for code scanning", "Providing
data to track code scanning alerts across runs":
https://docs.github.com/en/code-security/code-scanning/integrating-with-code-scanning/sarif-support-for-code-scanning).
It leaves the line out, so an edit above a finding keeps its alert.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any, TextIO
from urllib.parse import quote_from_bytes

from ..model import INTERNAL_ERROR_RULE, Finding, FixInfo, Report, RuleInfo, Severity
from ..paths import display_path, layer_file, printable, repository_root
from . import FormatOptions, json_text, statistics
from .fingerprints import Occurrences

SARIF_VERSION = "2.1.0"
SARIF_SCHEMA = (
    "https://docs.oasis-open.org/sarif/sarif/v2.1.0/errata01/os/schemas/sarif-schema-2.1.0.json"
)
SRCROOT = "SRCROOT"
_LEVEL = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.INFO: "note"}
#: GitHub code scanning limits a rule's short and full descriptions to 1024
#: characters ("SARIF support for code scanning", reportingDescriptor); the
#: documentation in full is the rule's help, which has no such limit.
DESCRIPTION_LIMIT = 1024
#: The key of the finding's fingerprint in ``partialFingerprints``: a versioned
#: hierarchical string (SARIF 2.1.0, result.partialFingerprints); never ``primaryLocationLineHash``,
#: the line hash upload-sarif computes and checks against what it finds there.
FINGERPRINT_KEY = "usdrenderLintFinding/v1"
#: What a viewer reads as an embedded link in a plain text message, ``[text](n)``
#: (SARIF 2.1.0 §3.11.6, "Messages with embedded links").
_EMBEDDED_LINK = re.compile(r"\[[^\[\]]*\]\(")
_LINK_CHARACTER = re.compile(r"([\\\[\]])")


def artifact_location(path: Path, root: Path) -> dict[str, str]:
    """A URI relative to ``root`` when the file is below it, else absolute."""
    try:
        relative = path.relative_to(root)
    except ValueError:
        return {"uri": path.as_uri()}
    # Percent-encoded bytes: a file name that is not UTF-8 stays exact.
    return {"uri": quote_from_bytes(os.fsencode(relative.as_posix())), "uriBaseId": SRCROOT}


def folder_uri(folder: Path) -> str:
    """``folder``'s file URI ending in ``/``, as SARIF wants a base URI: the
    root folder is ``file:///`` (not ``file:/``, stripping the URI's own slashes)."""
    uri = folder.as_uri()
    return uri if uri.endswith("/") else uri + "/"


def message_text(text: str) -> str:
    """A result's or notification's message, which quotes asset paths, layer
    names and values from the user's files, as SARIF's plain text carries it
    for a viewer to show it as written (SARIF 2.1.0 Plus Errata 01,
    https://docs.oasis-open.org/sarif/sarif/v2.1.0/errata01/os/sarif-v2.1.0-errata01-os-complete.html):

    - controls escaped as the text report escapes them;
    - ``{`` and ``}`` doubled (§3.11.5, "Messages with placeholders": ``{0}``
      is a placeholder a viewer fills from the message's ``arguments``);
    - in a message where ``[text](...)`` would read as an embedded link
      (§3.11.6), every backslash and square bracket escaped with a backslash,
      as in a link's text. SARIF 2.2's draft lets a producer escape them
      anywhere and asks it to where a link could be misread (oasis-tcs/sarif-spec
      pull request 768); CodeQL, whose results code scanning shows, escapes them
      (github/vscode-codeql issue 1104). Any other square brackets (a USD
      array's) stay as they are, which §3.11.6 allows.

    A rule's descriptions and help take no ``arguments`` and are left as written."""
    text = printable(text, keep="\n").replace("{", "{{").replace("}", "}}")
    if _EMBEDDED_LINK.search(text):
        text = _LINK_CHARACTER.sub(r"\\\1", text)
    return text


def description(text: str) -> str:
    """``text`` cut to DESCRIPTION_LIMIT characters at a word, marked ``…``."""
    if len(text) <= DESCRIPTION_LIMIT:
        return text
    words = text[: DESCRIPTION_LIMIT - 1].rsplit(None, 1)
    return words[0].rstrip() + "…"


def _descriptor(rule: RuleInfo, unfixable: frozenset[str]) -> dict[str, Any]:
    """The rule as this run has it: no fix for one the configuration makes
    ``unfixable`` (its results carry none either), whatever its class."""
    return {
        "id": rule.code,
        "name": rule.name,
        "shortDescription": {"text": description(rule.summary or rule.name)},
        "fullDescription": {"text": description(rule.summary or rule.name)},
        # Code scanning shows the Markdown help instead of the text: none when empty.
        "help": {"text": rule.doc or rule.summary or rule.name}
        | ({"markdown": rule.doc} if rule.doc else {}),
        "defaultConfiguration": {"level": _LEVEL[rule.severity]},
        "properties": {"fix": "none" if rule.code in unfixable else rule.fix},
    } | ({"helpUri": rule.url} if rule.url else {})


def _rules(report: Report) -> list[RuleInfo]:
    """The rules that ran, plus one entry per code a finding carries without a
    registered rule (the reserved internal-error code), so every result's
    ``ruleId`` is described."""
    rules = {rule.code: rule for rule in report.rules}
    for finding in report.findings:
        if finding.code == INTERNAL_ERROR_RULE.code:
            rules.setdefault(finding.code, INTERNAL_ERROR_RULE)
        elif finding.code not in rules:
            rules[finding.code] = RuleInfo(
                finding.code, finding.name, finding.severity, finding.name, ""
            )
    return sorted(rules.values(), key=lambda rule: rule.code)


def rule_overrides(report: Report, rules: list[RuleInfo]) -> list[dict[str, Any]]:
    """The levels the run's configuration gives its rules instead of their
    defaults, as SARIF 2.1.0 records a tool configured at run time: a rule's
    ``defaultConfiguration`` is the tool's default (§3.49.14), and the
    invocation's ``ruleConfigurationOverrides`` (§3.20.5) holds one
    ``configurationOverride`` (§3.51) per rule reconfigured, whose ``descriptor``
    (§3.51.2) names the rule by index and id (§3.52) and ``configuration.level``
    (§3.51.3) its level: the order a result's level is found in (§3.27.10).
    Each result still states its level, so no viewer has to resolve it. A run
    whose files were linted under configurations that differ about a rule has
    one override per level, its ``properties`` naming the configuration files
    that set it."""
    if not report.severities and not report.severities_by_file:
        return []
    # Each configuration's severities once, with the files linted under it.
    by_file = dict(report.severities_by_file)
    configured: dict[tuple[tuple[str, Severity], ...], set[str]] = {}
    for result in report.files:
        severities = by_file.get(result.file, report.severities)
        configured.setdefault(severities, set()).add(result.config or "")
    overrides: list[dict[str, Any]] = []
    for index, rule in enumerate(rules):
        levels: dict[str, set[str]] = {}
        for severities, configs in configured.items():
            level = _LEVEL[dict(severities).get(rule.code, rule.severity)]
            levels.setdefault(level, set()).update(configs)
        default = _LEVEL[rule.severity]
        for level in sorted(set(levels) - {default}):
            override: dict[str, Any] = {
                "descriptor": {"id": rule.code, "index": index},
                "configuration": {"level": level},
            }
            if len(levels) > 1:
                named = sorted(display_path(config) for config in levels[level] if config)
                override["properties"] = {"configurationFiles": named}
            overrides.append(override)
    return overrides


def _result(
    finding: Finding, index: int, root: Path, occurrences: Occurrences, fix: FixInfo | None
) -> dict[str, Any]:
    loc = finding.location
    result: dict[str, Any] = {
        "ruleId": finding.code,
        "ruleIndex": index,
        "level": _LEVEL[finding.severity],
        # A viewer prints the text: controls escaped, its length bounded (JSON keeps it).
        "message": {"text": message_text(finding.message)},
        "partialFingerprints": {FINGERPRINT_KEY: occurrences.fingerprint(finding)},
    }
    location: dict[str, Any] = {}
    file = layer_file(loc.layer) or layer_file(loc.file)
    if file is not None:
        physical: dict[str, Any] = {"artifactLocation": artifact_location(file, root)}
        if loc.line and loc.layer and layer_file(loc.layer) == file:
            physical["region"] = {"startLine": loc.line}
            if loc.column:
                physical["region"]["startColumn"] = loc.column
        else:
            # Code scanning requires region.startLine, and upload-sarif computes
            # no fingerprint without it: a whole-file finding is at the file's
            # start, as in the GitLab report.
            physical["region"] = {"startLine": 1}
        location["physicalLocation"] = physical
    if loc.path:
        is_property = "." in loc.path.rsplit("/", 1)[-1]
        location["logicalLocations"] = [
            {
                "fullyQualifiedName": loc.path,
                "name": loc.path.rsplit("/", 1)[-1].rsplit(".", 1)[-1] or loc.path,
                "kind": "member" if is_property else "object",
            }
        ]
    if location:
        result["locations"] = [location]
    properties: dict[str, Any] = {}
    if fix is not None:  # Report.offered_fix: none the baseline holds back
        properties["fix"] = {"description": fix.description, "safe": fix.safe}
    if finding.profile is not None:
        properties["profile"] = finding.profile
        properties["profileReason"] = finding.profile_reason
    if properties:
        result["properties"] = properties
    return result


def report_to_sarif(report: Report, options: FormatOptions, root: Path) -> dict[str, Any]:
    rules = _rules(report)
    unfixable = report.unfixable_everywhere()
    index = {rule.code: position for position, rule in enumerate(rules)}
    occurrences = Occurrences(str(root))
    notifications = [
        {
            "level": "error",
            "message": {
                "text": message_text(result.error or f"{result.file}: could not be linted")
            },
            "locations": [{"physicalLocation": {"artifactLocation": artifact_location(file, root)}}]
            if (file := layer_file(result.file)) is not None
            else [],
        }
        for result in report.errored_files
    ]
    overrides = rule_overrides(report, rules)
    run: dict[str, Any] = {
        "tool": {
            "driver": {
                "name": options.tool_name,
                "version": options.tool_version,
                "rules": [_descriptor(rule, unfixable) for rule in rules],
            }
        },
        "originalUriBaseIds": {SRCROOT: {"uri": folder_uri(root)}},
        # A finding's column counts characters, not UTF-16 units (SARIF's default).
        "columnKind": "unicodeCodePoints",
        "invocations": [
            {
                "executionSuccessful": not notifications,
                "toolExecutionNotifications": notifications,
            }
            | ({"ruleConfigurationOverrides": overrides} if overrides else {})
        ],
        "results": [
            _result(f, index[f.code], root, occurrences, report.offered_fix(f))
            for f in report.findings
            if options.show_info or f.severity != Severity.INFO
        ],
    }
    if options.statistics:
        run["properties"] = {"statistics": statistics(report)}
    return {"$schema": SARIF_SCHEMA, "version": SARIF_VERSION, "runs": [run]}


class SarifFormatter:
    #: It never reads the configuration digest, so the command does not compute it.
    reads_configuration = False

    def render(self, report: Report, stream: TextIO, options: FormatOptions) -> None:
        root = repository_root() or os.getcwd()
        stream.write(json_text(report_to_sarif(report, options, Path(root).resolve())))
