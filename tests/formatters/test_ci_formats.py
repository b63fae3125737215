"""The GitLab Code Quality and JUnit XML formats, from real files, read back as
GitLab and a JUnit reader (Jenkins, GitLab, Azure) would."""

from __future__ import annotations

import io
import json
import os
import re
import shutil
from pathlib import Path
from xml.etree import ElementTree

import pytest
from click.testing import CliRunner, Result

from usdrender_lint.cli import cli
from usdrender_lint.formatters import FormatOptions, load_formatter
from usdrender_lint.formatters.gitlab import NOT_LINTED_CODE as GITLAB_NOT_LINTED
from usdrender_lint.formatters.junit import NOT_LINTED_CODE as JUNIT_NOT_LINTED
from usdrender_lint.model import FileResult, Finding, FixInfo, Location, Report, Severity
from usdrender_lint.paths import escape

pytestmark = pytest.mark.heavy(seconds=11)

REPO = Path(__file__).parents[2]
#: Copied into each test's working directory: findings of every severity, a
#: file USD cannot parse (ST001), a clean file, findings in a sublayer two
#: stages share.
SOURCES = (
    REPO / "examples" / "broken_shot",
    REPO / "examples" / "clean_shot",
    REPO / "examples" / "framing_shot",
    REPO / "tests" / "rules" / "SE003_data_window_malformed",
)
#: What the paths given to check name, relative to the working directory.
TARGETS = ("broken_shot", "clean_shot", "framing_shot", "SE003_data_window_malformed")
GITLAB_SEVERITY = {"error": "critical", "warning": "minor", "info": "info"}
#: Jenkins' xunit plugin's junit-10.xsd: the attributes each element may carry.
JUNIT_ATTRIBUTES = {
    "testsuites": {"name", "time", "tests", "failures", "errors"},
    "testsuite": {"name", "tests", "failures", "errors", "time", "skipped", "timestamp"},
    "testcase": {"name", "time", "classname", "group"},
    "failure": {"type", "message"},
    "error": {"type", "message"},
}
JUNIT_REQUIRED = {
    "testsuite": {"name", "tests", "failures", "errors"},
    "testcase": {"name"},
}
#: Characters XML 1.0 cannot carry at all (not even as references).
NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")


def check(*args: str) -> Result:
    return CliRunner().invoke(cli, ["check", "--isolated", "--jobs", "1", "--timeout", "0", *args])


def run(fmt: str, *args: str, code: int = 1) -> str:
    result = check("--format", fmt, *args)
    assert result.exit_code == code, result.output
    # Whatever a name holds, the report is valid UTF-8.
    return result.stdout_bytes.decode("utf-8")


@pytest.fixture
def workspace(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A repository root as the working directory, holding the sources and
    ``notes.usda``, a file that is not USD."""
    root = tmp_path / "repo"
    for source in SOURCES:
        shutil.copytree(source, root / source.name)
    (root / "notes.usda").write_text("these are notes, not a layer\n")
    monkeypatch.chdir(root)
    return root


def json_files(*args: str, code: int = 1) -> list[dict]:
    return json.loads(run("json", *args, code=code))["files"]


def shown(finding: dict, show_info: bool) -> bool:
    return show_info or finding["severity"] != "info"


def render(fmt: str, report: Report, **options: object) -> str:
    stream = io.StringIO()
    load_formatter(fmt).render(report, stream, FormatOptions(**options))
    return stream.getvalue()


def _twice(message: str = "bad", name: str = "shot.usda") -> Report:
    """Two identical findings (a rule that reports the same thing twice)."""
    finding = Finding(
        "SE003", "data-window-malformed", Severity.ERROR, message, Location(name, "/R", name, 3)
    )
    return Report((FileResult(name, findings=(finding, finding)),))


# -- GitLab Code Quality ---------------------------------------------------------


@pytest.mark.parametrize("show_info", [False, True])
def test_gitlab_has_an_issue_per_finding_and_per_file_not_linted(workspace, show_info) -> None:
    info = ("--show-info",) if show_info else ()
    args = (*info, *TARGETS, "notes.usda", "missing.usda")
    files = json_files(*args, code=2)
    issues = json.loads(run("gitlab", *args, code=2))
    assert isinstance(issues, list)
    expected = [
        (f["code"], GITLAB_SEVERITY[f["severity"]], f["layer"] or f["file"], f["line"] or 1)
        for entry in files
        for f in entry["findings"]
        if shown(f, show_info)
    ]
    not_linted = [issue for issue in issues if issue["severity"] == "blocker"]
    assert [(i["check_name"], i["location"]["path"]) for i in not_linted] == [
        ("ST001", "missing.usda")
    ]
    assert "missing.usda: no such file" in not_linted[0]["description"]
    got = [
        (i["check_name"], i["severity"], i["location"]["path"], i["location"]["lines"]["begin"])
        for i in issues
        if i["severity"] != "blocker"
    ]
    assert got == expected
    assert ("info" in {i["severity"] for i in issues}) is show_info
    # The file that is not USD, and one USD cannot parse, are findings (ST001).
    assert {("ST001", "notes.usda"), ("ST001", "broken_shot/lighting_wip.usda")} <= {
        (i["check_name"], i["location"]["path"]) for i in issues
    }
    for issue in issues:
        assert set(issue) == {"description", "check_name", "fingerprint", "severity", "location"}
        path = issue["location"]["path"]
        assert not os.path.isabs(path) and not path.startswith("./")
        assert path == "missing.usda" or (workspace / path).is_file()
        assert "\n" not in issue["description"] and issue["check_name"] in issue["description"]
        assert re.fullmatch("[0-9a-f]{64}", issue["fingerprint"])
    assert len({i["fingerprint"] for i in issues}) == len(issues)


def test_gitlab_names_the_layer_and_its_line_and_the_stage(workspace) -> None:
    issues = json.loads(run("gitlab", "--select", "SE003", "SE003_data_window_malformed"))
    shared = [i for i in issues if i["location"]["path"].endswith("bad_window_layer.usda")]
    # Two stages sublayer or reference the layer: one issue each, told apart.
    assert len(shared) >= 2
    assert {i["location"]["lines"]["begin"] for i in shared} == {7}
    assert len({i["fingerprint"] for i in shared}) == len(shared)
    assert all("(stage SE003_data_window_malformed/fail_from_" in i["description"] for i in shared)


def test_gitlab_fingerprints_are_the_same_on_every_run_and_checkout(
    workspace, tmp_path, monkeypatch
) -> None:
    def fingerprints(*args: str) -> list[str]:
        return [i["fingerprint"] for i in json.loads(run("gitlab", *args, code=2))]

    named = (*TARGETS, "missing.usda")
    first = fingerprints(*named)
    assert len(first) > len(TARGETS) and first == fingerprints(*named)
    # The files named absolutely: the same paths, relative to the working directory.
    assert first == fingerprints(*(str(workspace / target) for target in named))
    # Another checkout, elsewhere on the machine (or another machine).
    other = tmp_path / "elsewhere" / "clone"
    shutil.copytree(workspace, other)
    monkeypatch.chdir(other)
    assert first == fingerprints(*named)


@pytest.mark.parametrize("where", ["broken_shot", "SE003_data_window_malformed"])
def test_gitlab_names_files_from_the_repository_root_in_a_subfolder(
    workspace, monkeypatch, where
) -> None:
    """GitLab reads location.path as "a relative path in the repository": a job
    run from a subfolder of the checkout writes the report of its root."""
    (workspace / ".git").mkdir()  # a work tree's root, as git init makes it
    named = [str(workspace / target) for target in TARGETS]
    from_root = json.loads(run("gitlab", *named))
    paths = {issue["location"]["path"] for issue in from_root}
    assert "broken_shot/shot.usda" in paths
    assert all(path.startswith(TARGETS) for path in paths)
    monkeypatch.chdir(workspace / where)
    assert json.loads(run("gitlab", *named)) == from_root


def test_gitlab_identical_findings_get_distinct_stable_fingerprints() -> None:
    issues = json.loads(render("gitlab", _twice()))
    assert len(issues) == 2 and issues[0]["fingerprint"] != issues[1]["fingerprint"]
    assert json.loads(render("gitlab", _twice())) == issues
    assert json.loads(render("gitlab", _twice("other")))[0]["fingerprint"] not in {
        i["fingerprint"] for i in issues
    }


def test_gitlab_and_junit_name_a_file_not_linted_as_the_engine_does() -> None:
    from usdrender_lint.engine import STAGE_OPEN_FAILED_CODE

    assert GITLAB_NOT_LINTED == JUNIT_NOT_LINTED == STAGE_OPEN_FAILED_CODE


# -- JUnit XML ------------------------------------------------------------------------


def junit(*args: str, code: int = 1) -> ElementTree.Element:
    text = run("junit", *args, code=code)
    assert text.startswith('<?xml version="1.0" encoding="UTF-8"?>\n')
    root = ElementTree.fromstring(text.encode("utf-8"))
    assert_schema(root)
    return root


def assert_schema(root: ElementTree.Element) -> None:
    """The elements, attributes and counts of Jenkins' junit-10.xsd, and test
    case names unique in their suite (GitLab keeps only the first of a name)."""
    assert root.tag == "testsuites"
    totals = {"tests": 0, "failures": 0, "errors": 0}
    for element in root.iter():
        assert set(element.attrib) <= JUNIT_ATTRIBUTES[element.tag], element.tag
        assert JUNIT_REQUIRED.get(element.tag, set()) <= set(element.attrib), element.tag
    for suite in root:
        assert suite.tag == "testsuite"
        cases = list(suite)
        assert all(case.tag == "testcase" for case in cases)
        assert all(case.get("classname") == suite.get("name") for case in cases)
        assert len({case.get("name") for case in cases}) == len(cases)
        counts = {
            "tests": len(cases),
            "failures": sum(case.find("failure") is not None for case in cases),
            "errors": sum(case.find("error") is not None for case in cases),
        }
        assert {key: int(suite.get(key, "")) for key in counts} == counts
        for key, count in counts.items():
            totals[key] += count
        for case in cases:
            assert len(case) <= 1 and all(child.tag in ("failure", "error") for child in case)
    assert {key: int(root.get(key, "")) for key in totals} == totals


@pytest.mark.parametrize("show_info", [False, True])
def test_junit_has_a_suite_per_file_and_a_failure_per_finding(workspace, show_info) -> None:
    info = ("--show-info",) if show_info else ()
    args = (*info, *TARGETS, "notes.usda", "missing.usda")
    files = json_files(*args, code=2)
    root = junit(*args, code=2)
    suites = {suite.get("name"): suite for suite in root}
    assert list(suites) == [entry["file"] for entry in files]
    for entry in files:
        suite = suites[entry["file"]]
        findings = [f for f in entry["findings"] if shown(f, show_info)]
        failures = [case.find("failure") for case in suite]
        if entry["status"] != "linted":
            (case,) = suite
            error = case.find("error")
            assert case.get("name") == "lint" and error is not None
            assert error.get("type") == "ST001"
            assert error.get("message") == "missing.usda: no such file"
        elif not findings:  # passes: one test case, nothing in it
            assert [(case.get("name"), len(case)) for case in suite] == [("lint", 0)]
        else:
            assert len(failures) == len(findings)
            for failure, finding in zip(failures, findings, strict=True):
                assert_failure(failure, finding)
    framing = suites["framing_shot/shot.usda"]
    assert int(framing.get("failures", "")) == (2 if show_info else 0)
    assert root.get("errors") == "1"


def test_junit_classnames_read_as_jenkins_splits_them(workspace) -> None:
    """Jenkins splits a classname at its last dot into package and class
    (junit-plugin's CaseResult.getPackageName/getSimpleName): a file's path
    becomes the package of its path without the extension and the class of
    the extension, one per file, so no two files' test cases are merged."""
    root = junit(*TARGETS, "notes.usda")
    seen: dict[tuple[str, str], str] = {}
    for suite in root:
        path = suite.get("name")
        for case in suite:
            classname = case.get("classname")
            assert classname == path
            package, _dot, simple = classname.rpartition(".")
            assert (package, simple) == (str(Path(path).with_suffix("")), Path(path).suffix[1:])
            assert seen.setdefault((package, simple), path) == path


@pytest.mark.parametrize("where", ["broken_shot", "SE003_data_window_malformed"])
def test_junit_names_files_from_the_repository_root_in_a_subfolder(
    workspace, monkeypatch, where
) -> None:
    """As the GitLab and SARIF reports: a job run from a subfolder of the
    checkout names the files (suites, classnames, where a failure is) as one
    run from its root, so its test view compares with the root job's."""
    (workspace / ".git").mkdir()  # a work tree's root, as git init makes it
    named = [str(workspace / target) for target in TARGETS]
    from_root = run("junit", *named)
    suites = [suite.get("name") for suite in ElementTree.fromstring(from_root)]
    assert "broken_shot/shot.usda" in suites
    assert all(name.startswith(TARGETS) for name in suites)
    monkeypatch.chdir(workspace / where)
    assert run("junit", *named) == from_root


def assert_failure(failure: ElementTree.Element | None, finding: dict) -> None:
    """The failure of a finding of the JSON report: its code, its message, and
    a text that says where, how bad, on what, and the fix."""
    assert failure is not None and failure.text is not None
    assert (failure.get("type"), failure.get("message")) == (finding["code"], finding["message"])
    where = finding["layer"] or finding["file"]
    if finding["line"]:
        where += f":{finding['line']}"
    head, *body = failure.text.splitlines()
    assert head == f"{where}: {finding['severity']} {finding['code']} {finding['name']}"
    assert finding["message"] in body
    if finding["path"]:
        assert f"path: {finding['path']}" in body
    if finding["fix"]:
        safety = "fix" if finding["fix"]["safe"] else "unsafe fix"
        assert f"{safety}: {finding['fix']['description']}" in body


def test_junit_repeated_test_names_are_numbered() -> None:
    root = ElementTree.fromstring(render("junit", _twice()).encode("utf-8"))
    assert_schema(root)
    assert [case.get("name") for case in root.iter("testcase")] == [
        "SE003 data-window-malformed /R",
        "SE003 data-window-malformed /R #2",
    ]


# -- both ------------------------------------------------------------------------------


@pytest.mark.parametrize("fmt", ["gitlab", "junit"])
def test_statistics_leave_the_document_as_it_is(workspace, fmt) -> None:
    assert run(fmt, "--statistics", *TARGETS) == run(fmt, *TARGETS)


@pytest.mark.parametrize("fmt", ["gitlab", "junit"])
def test_output_file_gets_what_stdout_would(workspace, tmp_path, fmt) -> None:
    target = tmp_path / "report.out"
    result = check("--format", fmt, "--output", str(target), *TARGETS)
    assert result.exit_code == 1 and result.stdout == ""
    assert target.read_text(encoding="utf-8") == run(fmt, *TARGETS)


@pytest.mark.parametrize("fmt", ["gitlab", "junit"])
def test_merge_writes_what_one_check_would(workspace, tmp_path, fmt) -> None:
    reports = []
    for index, target in enumerate(TARGETS):
        reports.append(str(tmp_path / f"report-{index}.json"))
        check("--format", "json", "--output", reports[-1], "--fail-on", "never", target)
    merged = CliRunner().invoke(cli, ["merge", "--isolated", "--format", fmt, *reports])
    assert merged.exit_code == 1, merged.output
    # The same issues and suites (merge orders the files by name).
    assert _parts(fmt, merged.stdout) == _parts(fmt, run(fmt, *TARGETS))


def _parts(fmt: str, text: str) -> list[str]:
    if fmt == "gitlab":
        return sorted(json.dumps(issue, sort_keys=True) for issue in json.loads(text))
    root = ElementTree.fromstring(text.encode("utf-8"))
    assert_schema(root)
    return sorted(ElementTree.tostring(suite, encoding="unicode").strip() for suite in root)


def _hostile_report(name: str, message: str) -> Report:
    finding = Finding(
        "SE006",
        "aspect-ratio-conform-policy-invalid",
        Severity.ERROR,
        message,
        Location(name, "/R/S.aspectRatioConformPolicy", name, 6),
        FixInfo("set <\x1b> & go", safe=False),
    )
    return Report(
        (
            FileResult(name, findings=(finding,)),
            FileResult(name + "2", "error", f"{name}2: {message}"),
        )
    )


@pytest.mark.parametrize(
    "name",
    [
        "shot\x1b[2J\nfake.usda",
        os.fsdecode(b"caf\xe9 x.usda"),
        "渲染 é.usda",
    ],
    ids=["controls", "not-utf8", "unicode"],
)
def test_names_and_messages_keep_both_documents_valid(name: str) -> None:
    message = "x\x1b]0;pwned\x07\nforged\x00 \ufffe end"
    gitlab = render("gitlab", _hostile_report(name, message), show_info=True)
    issues = json.loads(gitlab.encode("utf-8"))
    assert [i["location"]["path"] for i in issues] == [escape(name), escape(name + "2")]
    # Printed in a merge request: no control characters, one line.
    assert not any(re.search("[\x00-\x1f\x7f-\x9f]", i["description"]) for i in issues)
    assert len({i["fingerprint"] for i in issues}) == 2

    # XML 1.0 forbids a surrogate that is no byte of a name (a merged report can hold one).
    text = render("junit", _hostile_report(name, message + " \ud800"), show_info=True)
    assert not NOT_XML.search(text.replace("\n", ""))
    root = ElementTree.fromstring(text.encode("utf-8"))  # well-formed XML 1.0
    assert_schema(root)
    failure = root.find("testsuite/testcase/failure")
    assert failure is not None and failure.text is not None
    assert failure.get("message") == "x\\x1b]0;pwned\\x07\\nforged\\x00 \\ufffe end \\ud800"
    assert "unsafe fix: set <\\x1b> & go" in failure.text
    if name.isprintable():
        assert root.find("testsuite").get("name") == escape(name)  # type: ignore[union-attr]


def test_a_file_named_in_another_encoding_is_linted_and_reported(tmp_path, monkeypatch) -> None:
    try:
        name = os.fsdecode(b"caf\xe9 x.usda")
        shutil.copy(SOURCES[3] / "fail_inverted.usda", tmp_path / name)
    except (OSError, UnicodeError):
        pytest.skip("the file system takes only UTF-8 names")
    monkeypatch.chdir(tmp_path)
    issues = json.loads(run("gitlab", "--select", "SE003", name))
    assert [(i["location"]["path"], i["location"]["lines"]["begin"]) for i in issues] == [
        ("caf\\xe9 x.usda", 8)
    ]
    root = junit("--select", "SE003", name)
    assert [suite.get("name") for suite in root] == ["caf\\xe9 x.usda"]
