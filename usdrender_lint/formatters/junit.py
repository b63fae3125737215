"""JUnit XML, for the test views of CI systems: GitLab's
``artifacts: reports: junit:``, Jenkins' ``junit`` step, Azure Pipelines'
PublishTestResults.

``<testsuites>`` holds one ``<testsuite>`` per linted file, named by the file
relative to the root of the Git work tree the working directory is in (else
to the working directory), as is each of its test cases' ``classname``
(GitLab lists a test case under its classname), and as the GitLab and SARIF
reports name files: a CI page shows the repository's files, and a job run
from a subfolder of the checkout (``cd``, ``dir()``) names them as one run
from its root, so the test views of the two compare. Each finding is a
``<testcase>`` holding a ``<failure>``: ``type`` is the rule code, ``message``
the message on one line, the text the layer and line, severity, code and name,
the prim or property path, the message, the fix and the stage. A file with no
finding is one passing test case, ``lint``; a file that could not be linted is
that test case with an ``<error>``. ``tests``, ``failures`` and ``errors``
count them, per file and in all.

The elements and attributes are those of the JUnit schema Jenkins' xunit
plugin validates with (junit-10.xsd:
https://github.com/jenkinsci/xunit-plugin/blob/master/src/main/resources/org/jenkinsci/plugins/xunit/types/model/xsd/junit-10.xsd),
the ones GitLab reads
(https://docs.gitlab.com/ci/testing/unit_test_reports/#junit-xml-format-specification):
no ``time`` or ``timestamp`` (the report has neither), no ``file`` (not in that
schema; the text names the layer). GitLab keeps only the first of test cases
with the same name, so a repeated name gets `` #2``, `` #3``...

- The classname is the file's path as it is, dots included: GitLab and Azure
  Pipelines show it whole. Jenkins reads a classname as ``package.Class`` and
  splits it at its last dot (``CaseResult.getPackageName``,
  https://github.com/jenkinsci/junit-plugin/blob/master/src/main/java/hudson/tasks/junit/CaseResult.java),
  which in a file's path is the extension's: Jenkins lists each file as the
  package of its path without the extension (``shots/010/shot``) holding one
  class, the extension (``usda``). No two files share a package and class, so
  nothing is merged; replacing the dots instead would show every reader a
  name that is not the file's.
- Info findings only with --show-info, as in the text and GitHub reports.
- --statistics adds nothing: in that schema ``<testsuites>`` holds test suites
  only, and a suite of counts would read as tests.
- Every text is XML 1.0: control characters (XML 1.0 cannot carry most of
  them, even as references) are written ``\\x1b``, a name that is not UTF-8
  in the lossless form of :func:`usdrender_lint.paths.escape`, and
  ElementTree escapes the markup.
"""

from __future__ import annotations

import re
from typing import TextIO
from xml.etree import ElementTree

from ..model import FileResult, Finding, FixInfo, Report, Severity
from ..paths import display_path, layer_file, printable, relative_in, repository_root
from . import HELD_BY_BASELINE, FormatOptions, shown_fix

#: The test case of a file as a whole: passing, or with the reason it could not be linted.
FILE_TEST = "lint"
#: engine.stage.STAGE_OPEN_FAILED_CODE (not imported: that module loads pxr),
#: the code a file no rule could check gets (running/documents.py).
NOT_LINTED_CODE = "ST001"
#: The attributes that count a suite's test cases, and all of them on ``<testsuites>``.
COUNTS = ("tests", "failures", "errors")
XML_DECLARATION = '<?xml version="1.0" encoding="UTF-8"?>\n'
#: What printable leaves and XML 1.0 forbids: surrogates that are no byte of a
#: file name (those are U+DC80-U+DCFF, which escape writes as bytes), and
#: U+FFFE and U+FFFF.
_NOT_XML = re.compile("[\ud800-\udc7f\udd00-\udfff\ufffe\uffff]")


def xml_text(text: str, keep: str = "") -> str:
    """``text`` as XML 1.0 carries it and a CI page shows it: printable (controls
    but those in ``keep`` escaped, its length bounded), with no character XML
    forbids."""
    return printable(_NOT_XML.sub(lambda m: f"\\u{ord(m.group()):04x}", text), keep=keep)


def _failure_text(finding: Finding, base: str | None, shown: tuple[FixInfo, bool] | None) -> str:
    loc = finding.location
    layer = layer_file(loc.layer)
    where = display_path(str(layer or loc.file), base)
    if layer is not None and loc.line:
        where += f":{loc.line}"
    lines = [f"{where}: {finding.severity} {finding.code} {finding.name}"]
    if loc.path:
        lines.append(f"path: {loc.path}")
    lines.append(finding.message)
    if shown is not None:  # formatters.shown_fix
        fix, held = shown
        kind = ("fix" if fix.safe else "unsafe fix") + (f", {HELD_BY_BASELINE}" if held else "")
        lines.append(f"{kind}: {fix.description}")
    stage = display_path(loc.file, base)
    if layer is not None and display_path(str(layer), base) != stage:
        lines.append(f"stage: {stage}")
    return "\n".join(xml_text(line, keep="\n") for line in lines) + "\n"


class _Suite:
    """One file's ``<testsuite>``, its test cases named uniquely."""

    def __init__(self, parent: ElementTree.Element, file: str, base: str | None) -> None:
        self.base = base
        self.name = xml_text(display_path(file, base))
        self.element = ElementTree.SubElement(parent, "testsuite", name=self.name)
        self.counts = dict.fromkeys(COUNTS, 0)
        self._names: dict[str, int] = {}

    def case(self, name: str) -> ElementTree.Element:
        count = self._names.get(name, 0) + 1
        self._names[name] = count
        unique = name if count == 1 else f"{name} #{count}"
        self.counts["tests"] += 1
        return ElementTree.SubElement(
            self.element, "testcase", name=xml_text(unique), classname=self.name
        )

    def fail(self, finding: Finding, shown: tuple[FixInfo, bool] | None) -> None:
        loc = finding.location
        name = " ".join(part for part in (finding.code, finding.name, loc.path) if part)
        failure = ElementTree.SubElement(self.case(name), "failure")
        failure.set("message", xml_text(finding.message))
        failure.set("type", xml_text(finding.code))
        failure.text = _failure_text(finding, self.base, shown)
        self.counts["failures"] += 1

    def error(self, result: FileResult) -> None:
        # Files in the message relative to the working directory, as in every message.
        reason = relative_in(result.error or f"{result.file}: could not be linted")
        error = ElementTree.SubElement(
            self.case(FILE_TEST), "error", message=xml_text(reason), type=NOT_LINTED_CODE
        )
        error.text = xml_text(f"could not be linted: {reason}", keep="\n") + "\n"
        self.counts["errors"] += 1

    def close(self) -> None:
        if not self.counts["tests"]:
            self.case(FILE_TEST)  # nothing found: the file passes
        for key, count in self.counts.items():
            self.element.set(key, str(count))


def report_to_junit(report: Report, options: FormatOptions) -> ElementTree.Element:
    root = ElementTree.Element("testsuites", name=xml_text(options.tool_name))
    totals = dict.fromkeys(COUNTS, 0)
    base = repository_root()
    for result in report.files:
        suite = _Suite(root, result.file, base)
        if result.status != "linted":
            suite.error(result)
        for finding in result.findings:
            if options.show_info or finding.severity != Severity.INFO:
                suite.fail(finding, shown_fix(report, finding))
        suite.close()
        for key, count in suite.counts.items():
            totals[key] += count
    for key, total in totals.items():
        root.set(key, str(total))
    return root


class JunitFormatter:
    #: It never reads Report.rules nor the configuration digest, so the
    #: command does not build them.
    reads_rules = False
    reads_configuration = False

    def render(self, report: Report, stream: TextIO, options: FormatOptions) -> None:
        root = report_to_junit(report, options)
        ElementTree.indent(root)
        stream.write(XML_DECLARATION + ElementTree.tostring(root, encoding="unicode") + "\n")
