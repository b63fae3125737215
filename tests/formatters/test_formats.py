"""SARIF and GitHub formats, --output and --statistics."""

from __future__ import annotations

import importlib
import json
import os
import re
import shutil
from pathlib import Path
from urllib.parse import quote

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.formatters import FormatOptions
from usdrender_lint.formatters.github import GithubFormatter, escape_data, escape_property
from usdrender_lint.formatters.sarif import (
    DESCRIPTION_LIMIT,
    FINGERPRINT_KEY,
    artifact_location,
    description,
    report_to_sarif,
)
from usdrender_lint.model import FileResult, Finding, Location, Report, RuleInfo, Severity

REPO = Path(__file__).parents[2]
SE003 = REPO / "tests" / "rules" / "SE003_data_window_malformed"
FROM_SUBLAYER = SE003 / "fail_from_sublayer.usda"
INVERTED = SE003 / "fail_inverted.usda"


def check(*args: str):
    return CliRunner().invoke(cli, ["check", "--isolated", "--jobs", "1", "--timeout", "0", *args])


@pytest.fixture
def in_repo(monkeypatch) -> Path:
    monkeypatch.chdir(REPO)
    return REPO


# -- SARIF ------------------------------------------------------------------------


def _sarif(*paths: str, extra: tuple[str, ...] = ()) -> dict:
    result = check("--format", "sarif", *extra, *paths)
    assert result.exit_code in (1, 2), result.output
    return json.loads(result.stdout)


def test_sarif_validates_against_the_official_schema(in_repo, shared_dir) -> None:
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads((shared_dir / "schemas" / "sarif-schema-2.1.0.json").read_text())
    document = _sarif(str(SE003), "missing.usda", extra=("--statistics",))
    jsonschema.Draft4Validator(schema).validate(document)
    assert document["version"] == "2.1.0"
    run = document["runs"][0]
    assert run["invocations"][0]["executionSuccessful"] is False
    notification = run["invocations"][0]["toolExecutionNotifications"][0]
    assert "missing.usda: no such file" in notification["message"]["text"]
    assert any(row["code"] == "SE003" for row in run["properties"]["statistics"])


def test_sarif_records_the_severities_the_configuration_sets(
    tmp_path, monkeypatch, shared_dir
) -> None:
    """A rule's defaultConfiguration is its default; the levels the project's
    configuration gives instead are the invocation's ruleConfigurationOverrides
    (SARIF 2.1.0 §3.20.5), per configuration file in a run split by them."""
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads((shared_dir / "schemas" / "sarif-schema-2.1.0.json").read_text())
    shutil.copy(INVERTED, tmp_path / "a.usda")
    (tmp_path / "usdrender-lint.toml").write_text('[severity]\nSE003 = "warning"\n')
    monkeypatch.chdir(tmp_path)

    def sarif(*args: str) -> dict:
        result = CliRunner().invoke(cli, ["check", "--jobs", "1", "--format", "sarif", *args])
        assert result.exit_code in (0, 1), result.output
        document = json.loads(result.stdout)
        jsonschema.Draft4Validator(schema).validate(document)
        return document["runs"][0]

    run = sarif(".")
    rules = run["tool"]["driver"]["rules"]
    index = next(i for i, rule in enumerate(rules) if rule["id"] == "SE003")
    assert rules[index]["defaultConfiguration"] == {"level": "error"}
    assert {r["level"] for r in run["results"] if r["ruleId"] == "SE003"} == {"warning"}
    assert run["invocations"][0]["ruleConfigurationOverrides"] == [
        {"descriptor": {"id": "SE003", "index": index}, "configuration": {"level": "warning"}}
    ]
    # A show with its own configuration: one override per level, naming its files.
    (tmp_path / "show").mkdir()
    shutil.copy(INVERTED, tmp_path / "show" / "a.usda")
    (tmp_path / "show" / "usdrender-lint.toml").write_text('[severity]\nSE003 = "info"\n')
    overrides = sarif(".", "--show-info")["invocations"][0]["ruleConfigurationOverrides"]
    assert [(o["configuration"]["level"], o["properties"]) for o in overrides] == [
        ("note", {"configurationFiles": ["show/usdrender-lint.toml"]}),
        ("warning", {"configurationFiles": ["usdrender-lint.toml"]}),
    ]
    # No severity configured: no overrides.
    run = sarif("--isolated", ".")
    assert "ruleConfigurationOverrides" not in run["invocations"][0]


def test_sarif_rules_carry_their_help_text(in_repo) -> None:
    run = _sarif(str(INVERTED), extra=("--select", "SE003,UL001"))["runs"][0]
    rules = {rule["id"]: rule for rule in run["tool"]["driver"]["rules"]}
    assert set(rules) == {"SE003", "UL001"}
    se003 = rules["SE003"]
    assert se003["name"] == "data-window-malformed"
    # The documentation explain prints, as text and as Markdown, for code scanning.
    explained = CliRunner().invoke(cli, ["explain", "SE003"]).stdout
    assert "## Why is this bad?" in explained and "## Under each profile" in explained
    assert se003["help"]["text"] == se003["help"]["markdown"] == explained
    assert all(rule["help"]["text"] for rule in rules.values())
    assert se003["defaultConfiguration"]["level"] == "error"
    assert rules["UL001"]["defaultConfiguration"]["level"] == "note"


def test_sarif_describes_st001_with_its_documentation_under_any_selection(in_repo) -> None:
    # ST001 is reported whatever --select says: its result's rule is the real one.
    broken = REPO / "examples" / "broken_shot"
    run = _sarif(str(broken), extra=("--select", "SE003"))["runs"][0]
    rules = {rule["id"]: rule for rule in run["tool"]["driver"]["rules"]}
    assert {result["ruleId"] for result in run["results"]} == set(rules) == {"SE003", "ST001"}
    explained = CliRunner().invoke(cli, ["explain", "ST001"]).stdout
    assert rules["ST001"]["help"] == {"text": explained, "markdown": explained}


def test_sarif_rule_descriptions_fit_code_scanning(in_repo) -> None:
    # GitHub code scanning takes at most 1024 characters in a rule's short and
    # full description; the documentation in full is its help.
    rules = _sarif(str(INVERTED))["runs"][0]["tool"]["driver"]["rules"]
    assert len(rules) > 20
    for rule in rules:
        for key in ("shortDescription", "fullDescription"):
            assert 0 < len(rule[key]["text"]) <= DESCRIPTION_LIMIT, (rule["id"], key)
    assert description("word " * 300) == ("word " * 204).rstrip() + "…"
    assert len(description("x" * 2000)) == DESCRIPTION_LIMIT


def test_sarif_result_locations(in_repo) -> None:
    run = _sarif(str(FROM_SUBLAYER), extra=("--select", "SE003"))["runs"][0]
    assert run["originalUriBaseIds"]["SRCROOT"]["uri"] == REPO.resolve().as_uri() + "/"
    (result,) = run["results"]
    assert run["tool"]["driver"]["rules"][result["ruleIndex"]]["id"] == result["ruleId"] == "SE003"
    assert result["level"] == "error"
    (location,) = result["locations"]
    physical = location["physicalLocation"]
    # The layer holding the opinion, not the linted root file.
    assert physical["artifactLocation"] == {
        "uri": "tests/rules/SE003_data_window_malformed/bad_window_layer.usda",
        "uriBaseId": "SRCROOT",
    }
    assert physical["region"] == {"startLine": 7}
    assert location["logicalLocations"] == [
        {
            "fullyQualifiedName": "/Render/Settings.dataWindowNDC",
            "name": "dataWindowNDC",
            "kind": "member",
        }
    ]


def test_sarif_whole_file_finding_is_at_line_one(in_repo) -> None:
    # ST003 is about the stage's metadata, with no line; code scanning needs one.
    unset = REPO / "tests" / "rules" / "ST003_render_settings_path_missing" / "fail_unset.usda"
    (result,) = _sarif(str(unset), extra=("--select", "ST003", "--fail-on", "info"))["runs"][0][
        "results"
    ]
    assert result["locations"][0]["physicalLocation"]["region"] == {"startLine": 1}


def test_sarif_describes_codes_without_a_rule_and_files_outside_the_root(tmp_path) -> None:
    internal = Finding("UL000", "internal-error", Severity.ERROR, "boom", Location("/x/a.usda"))
    report = Report((FileResult("/x/a.usda", findings=(internal,)),), rules=())
    run = report_to_sarif(report, FormatOptions(), tmp_path)["runs"][0]
    assert run["tool"]["driver"]["rules"][0]["id"] == "UL000"
    location = run["results"][0]["locations"][0]
    assert location["physicalLocation"]["artifactLocation"] == {"uri": "file:///x/a.usda"}
    # No line known: the file's start, as code scanning requires a region.startLine.
    assert location["physicalLocation"]["region"] == {"startLine": 1}
    assert "logicalLocations" not in location
    # A code no installed rule has (a merged report's plugin): no empty Markdown help.
    other = Finding("XY001", "gone-plugin", Severity.WARNING, "m", Location("/x/a.usda"))
    report = Report((FileResult("/x/a.usda", findings=(other,)),), rules=())
    [rule] = report_to_sarif(report, FormatOptions(), tmp_path)["runs"][0]["tool"]["driver"][
        "rules"
    ]
    assert rule["help"] == {"text": "gone-plugin"}
    assert artifact_location(tmp_path / "a b.usda", tmp_path) == {
        "uri": "a%20b.usda",
        "uriBaseId": "SRCROOT",
    }


@pytest.mark.parametrize("where", ["assets", "assets/SE003"])
def test_sarif_names_files_from_the_repository_root_in_a_subfolder(
    tmp_path, monkeypatch, where
) -> None:
    """Code scanning reads a relative URI as relative to the repository's root:
    run from a subfolder of the checkout, the report is the one from its root."""
    checkout = tmp_path / "checkout"
    shutil.copytree(SE003, checkout / "assets" / "SE003")
    (checkout / ".git").mkdir()  # a work tree's root, as git init makes it
    monkeypatch.chdir(checkout)
    from_root = _sarif("--select", "SE003", "assets/SE003")["runs"][0]
    uris = {
        result["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
        for result in from_root["results"]
    }
    assert uris and all(uri.startswith("assets/SE003/") for uri in uris)
    monkeypatch.chdir(checkout / where)
    run = _sarif("--select", "SE003", str(checkout / "assets" / "SE003"))["runs"][0]
    assert run["originalUriBaseIds"] == {"SRCROOT": {"uri": checkout.resolve().as_uri() + "/"}}
    assert run["results"] == from_root["results"]


def test_sarif_run_from_the_root_folder_has_a_file_uri_base(tmp_path) -> None:
    # Run from / (a container's default): the files are below it, relative to file:///.
    finding = Finding("SE003", "d", Severity.ERROR, "m", Location(str(tmp_path / "a b.usda")))
    report = Report((FileResult(str(tmp_path / "a b.usda"), findings=(finding,)),))
    run = report_to_sarif(report, FormatOptions(), Path("/"))["runs"][0]
    assert run["originalUriBaseIds"] == {"SRCROOT": {"uri": "file:///"}}
    location = run["results"][0]["locations"][0]["physicalLocation"]["artifactLocation"]
    assert location["uriBaseId"] == "SRCROOT"
    resolved = run["originalUriBaseIds"]["SRCROOT"]["uri"] + location["uri"]
    assert resolved == (tmp_path / "a b.usda").as_uri()
    assert report_to_sarif(report, FormatOptions(), tmp_path)["runs"][0]["originalUriBaseIds"] == {
        "SRCROOT": {"uri": tmp_path.as_uri() + "/"}
    }


def test_every_format_names_a_layer_as_its_file_when_run_from_the_root_folder(
    monkeypatch,
) -> None:
    """From /, OpenUSD names a layer opened by a relative path //tmp/...: every
    format names it as the file it is, relative to / as the file is."""
    monkeypatch.chdir("/")
    relative = str(INVERTED.relative_to("/"))
    args = ("--select", "SE003", relative)
    (entry,) = json.loads(check("--format", "json", *args).stdout)["files"]
    assert {finding["layer"] for finding in entry["findings"]} == {relative}
    text = check(*args).stdout
    assert f"{relative}:8: error SE003" in text and "(stage" not in text
    github = check("--format", "github", *args).stdout
    assert github.startswith(f"::error file={escape_property(str(INVERTED))},line=8,")
    (result,) = _sarif(*args)["runs"][0]["results"]
    uri = result["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
    assert uri == quote(relative)


def test_sarif_usdz_layer_is_the_package(tmp_path) -> None:
    finding = Finding(
        "SE003",
        "d",
        Severity.WARNING,
        "m",
        Location(str(tmp_path / "a.usdz"), "/R", f"{tmp_path}/a.usdz[inner.usda]", None),
    )
    rule = RuleInfo("SE003", "d", Severity.ERROR, "s", "doc")
    run = report_to_sarif(
        Report((FileResult("f", findings=(finding,)),), (rule,)), FormatOptions(), tmp_path
    )["runs"][0]
    assert run["results"][0]["level"] == "warning"
    physical = run["results"][0]["locations"][0]["physicalLocation"]
    assert physical["artifactLocation"]["uri"] == "a.usdz"


def _fingerprints(*args: str) -> list[tuple[str, str, dict]]:
    run = _sarif(*args)["runs"][0]
    return [
        (
            result["ruleId"],
            result["locations"][0]["physicalLocation"]["artifactLocation"]["uri"],
            result["partialFingerprints"],
        )
        for result in run["results"]
    ]


def test_sarif_results_carry_stable_fingerprints(tmp_path, monkeypatch) -> None:
    """Code scanning tracks an alert across commits by partialFingerprints:
    one per result, the GitLab report's value, the same on another checkout
    and after lines are added above the finding, distinct for identical
    findings."""
    for name in ("checkout", "clone"):
        shutil.copytree(SE003, tmp_path / name / "SE003")
    monkeypatch.chdir(tmp_path / "checkout")
    first = _fingerprints("--select", "SE003", "SE003")
    assert len(first) > 2
    assert all(list(prints) == [FINGERPRINT_KEY] for _code, _uri, prints in first)
    values = [prints[FINGERPRINT_KEY] for _code, _uri, prints in first]
    assert len(set(values)) == len(values)
    gitlab = json.loads(check("--format", "gitlab", "--select", "SE003", "SE003").stdout)
    assert values == [issue["fingerprint"] for issue in gitlab]
    monkeypatch.chdir(tmp_path / "clone")
    assert _fingerprints("--select", "SE003", "SE003") == first
    # Comments above every finding: lines move, alerts stay.
    for layer in Path("SE003").glob("*.usda"):
        text = layer.read_text()
        header, _newline, rest = text.partition("\n")
        layer.write_text(f"{header}\n# a note\n# another\n{rest}")
    assert _fingerprints("--select", "SE003", "SE003") == first
    # Two identical findings: two alerts.
    finding = Finding("SE003", "d", Severity.ERROR, "m", Location("a.usda", "/R", "a.usda", 3))
    report = Report((FileResult("a.usda", findings=(finding, finding)),))
    one, two = report_to_sarif(report, FormatOptions(), tmp_path)["runs"][0]["results"]
    assert one["partialFingerprints"] != two["partialFingerprints"]


# -- GitHub -----------------------------------------------------------------------


def test_github_escaping() -> None:
    assert escape_data("50% done\r\nnext: a,b") == "50%25 done%0D%0Anext: a,b"
    assert escape_property("a:b,c%\n") == "a%3Ab%2Cc%25%0A"


def _github(report: Report, show_info: bool = False) -> list[str]:
    import io

    stream = io.StringIO()
    GithubFormatter().render(report, stream, FormatOptions(show_info=show_info))
    return stream.getvalue().splitlines()


def test_github_annotations(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    layer = str(tmp_path / "lay,er:1.usda")
    findings = (
        Finding(
            "SE003",
            "data-window-malformed",
            Severity.ERROR,
            "bad 100%\nwindow",
            Location("shot.usda", "/R/S.dataWindowNDC", layer, 12),
        ),
        Finding(
            "CA006", "aspect", Severity.WARNING, "w", Location("shot.usda", "/R/S", None, None)
        ),
        Finding("ST003", "info-rule", Severity.INFO, "i", Location("shot.usda", None, layer, None)),
    )
    report = Report(
        (
            FileResult("shot.usda", findings=findings),
            FileResult("gone.usda", status="error", error="gone.usda: no such file"),
        )
    )
    lines = _github(report)
    here = escape_property(str(tmp_path))
    assert lines == [
        f"::error file={here}/lay%2Cer%3A1.usda,line=12,title=SE003::"
        "/R/S.dataWindowNDC: bad 100%25%0Awindow [data-window-malformed]",
        f"::warning file={here}/shot.usda,title=CA006::/R/S: w [aspect]",
        f"::error file={here}/gone.usda::could not be linted: gone.usda: no such file",
    ]
    assert (
        _github(report, show_info=True)[2]
        == f"::notice file={here}/lay%2Cer%3A1.usda,title=ST003::i [info-rule]"
    )


def _annotated_files(stdout: str) -> set[str]:
    """The files the runner annotates: it maps an absolute path below the
    workspace onto the repository and reads any other as relative to it
    (IssueCommandExtension in actions/runner's ActionCommandManager.cs)."""
    files = set()
    for line in stdout.splitlines():
        given = line.split("file=", 1)[1].split(",", 1)[0].split("::", 1)[0]
        given = given.replace("%3A", ":").replace("%2C", ",").replace("%25", "%")
        files.add(os.path.relpath(given, REPO) if os.path.isabs(given) else given)
    return files


@pytest.mark.parametrize("where", ["tests/rules", "/"])
def test_github_annotates_the_repository_file_from_any_working_directory(
    monkeypatch, where
) -> None:
    # A step with working-directory: set runs from a subfolder of the checkout.
    monkeypatch.chdir(REPO)
    from_root = _annotated_files(
        check("--format", "github", "--select", "SE003", str(SE003)).stdout
    )
    assert len(from_root) > 3
    assert all(f.startswith("tests/rules/SE003_data_window_malformed/") for f in from_root)
    monkeypatch.chdir(REPO / where)
    result = check("--format", "github", "--select", "SE003", str(SE003))
    assert result.exit_code == 1, result.output
    assert _annotated_files(result.stdout) == from_root


def test_github_format_from_the_command_line(in_repo) -> None:
    result = check("--format", "github", "--select", "SE003", str(INVERTED))
    assert result.exit_code == 1
    assert result.stdout == (
        f"::error file={escape_property(str(INVERTED))},line=8,"
        "title=SE003::/Render/Settings.dataWindowNDC: "
        + result.stdout.split("dataWindowNDC: ", 1)[1]
    )
    assert result.stdout.count("\n") == 1


# -- --output and --statistics ----------------------------------------------------


@pytest.mark.parametrize("output_format", ["text", "json", "sarif", "github"])
def test_output_file_gets_the_report_and_stdout_nothing(in_repo, tmp_path, output_format) -> None:
    target = tmp_path / "report.out"
    to_stdout = check("--format", output_format, str(INVERTED))
    to_file = check("--format", output_format, "--output", str(target), str(INVERTED))
    assert to_file.exit_code == to_stdout.exit_code == 1
    assert to_file.stdout == ""
    assert target.read_text(encoding="utf-8") == to_stdout.stdout
    assert [p.name for p in tmp_path.iterdir()] == ["report.out"]


def test_unwritable_output_is_exit_2(tmp_path) -> None:
    (tmp_path / "a_file").write_text("")  # a missing folder would be created
    result = check("--output", str(tmp_path / "a_file" / "report.txt"), str(INVERTED))
    assert result.exit_code == 2
    assert "cannot write the report" in result.stderr and "Traceback" not in result.output


def test_statistics_text(in_repo) -> None:
    result = check("--statistics", "--select", "SE003", str(SE003))
    tail = result.stdout.strip().splitlines()[-1]
    count = result.stdout.count(" error SE003 /")
    assert tail.split() == [str(count), "SE003", "error", "data-window-malformed"]
    assert "data-window-malformed" not in check("--select", "SE003", str(SE003)).stdout


def test_statistics_github_on_stdout(in_repo) -> None:
    # The annotations, then the counts as plain log lines, written to stdout
    # as a workflow step runs it (not into a test's StringIO).
    result = check("--format", "github", "--statistics", "--select", "SE003", str(SE003))
    assert result.exit_code == 1, result.output
    lines = result.stdout.strip().splitlines()
    count = sum(line.startswith("::error ") for line in lines)
    assert count and lines[-1].split() == [str(count), "SE003", "error", "data-window-malformed"]


def test_statistics_json_is_an_added_field(in_repo) -> None:
    plain = json.loads(check("--format", "json", "--select", "SE003", str(SE003)).stdout)
    assert "statistics" not in plain
    document = json.loads(
        check("--format", "json", "--statistics", "--select", "SE003", str(SE003)).stdout
    )
    assert {k: v for k, v in document.items() if k != "statistics"} == plain
    count = len([f for file in plain["files"] for f in file["findings"]])
    assert document["statistics"] == [
        {"code": "SE003", "name": "data-window-malformed", "severity": "error", "count": count}
    ]


# -- what a formatter is handed ------------------------------------------------------


def test_the_configuration_digest_is_computed_only_for_a_formatter_that_reads_it(
    monkeypatch, capsys
) -> None:
    """A formatter that says nothing is handed the digest; one that says
    ``reads_configuration = False`` is not, and it is not computed for it."""
    # The module, not the click command of its name that usdrender_lint.cli exports.
    command = importlib.import_module("usdrender_lint.cli.check")

    handed: list[str | None] = []

    class Reads:
        reads_rules = False

        def render(self, report, stream, options) -> None:
            handed.append(options.configuration)

    class Skips(Reads):
        reads_configuration = False

    asked: list[str] = []

    def digest() -> str:
        asked.append("digest")
        return "abc"

    for formatter in (Reads(), Skips()):
        monkeypatch.setattr(command, "load_formatter", lambda _name, *_, f=formatter: f)
        command.emit_report(Report(()), "any", (), FormatOptions(), None, digest)
    assert handed == ["abc", None]
    assert asked == ["digest"]
    capsys.readouterr()


@pytest.mark.parametrize("show_info", [False, True])
def test_sarif_has_info_findings_only_with_show_info(in_repo, show_info) -> None:
    """As the text, GitHub, GitLab and JUnit reports: an info finding is a
    result (level note) only with --show-info; the rules are described either way."""
    extra = ("--show-info",) if show_info else ()
    run = _sarif("examples", extra=extra)["runs"][0]
    findings = [
        f
        for file in json.loads(check("--format", "json", "examples").stdout)["files"]
        for f in file["findings"]
    ]
    shown = [f for f in findings if show_info or f["severity"] != "info"]
    expected = [(f["code"], f["severity"]) for f in shown]
    level = {"error": "error", "warning": "warning", "info": "note"}
    got = [(r["ruleId"], r["level"]) for r in run["results"]]
    assert got == [(code, level[severity]) for code, severity in expected]
    assert ("note" in {r["level"] for r in run["results"]}) is show_info
    rules = {rule["id"]: rule for rule in run["tool"]["driver"]["rules"]}
    infos = {f["code"] for f in findings if f["severity"] == "info"}
    assert infos and infos <= set(rules)
    for result in run["results"]:
        assert run["tool"]["driver"]["rules"][result["ruleIndex"]]["id"] == result["ruleId"]


def _as_a_viewer_shows(text: str) -> tuple[str, list[str]]:
    """A SARIF plain text message as a viewer reads it (SARIF 2.1.0 §3.11.5 and
    §3.11.6, backslash escapes as SARIF 2.2's draft and CodeQL read them): the
    text shown, and the placeholders and embedded links it would fill or link."""
    shown: list[str] = []
    read: list[str] = []
    i = 0
    while i < len(text):
        if text.startswith(("{{", "}}"), i):
            shown.append(text[i])
            i += 2
            continue
        if text[i] == "\\" and text[i + 1 : i + 2] in ("\\", "[", "]"):
            shown.append(text[i + 1])
            i += 2
            continue
        syntax = re.compile(r"\{\d+\}|\[(?:[^\\\[\]]|\\.)*\]\([^)]*\)").match(text, i)
        if syntax:
            read.append(syntax.group())
        shown.append(text[i])
        i += 1
    return "".join(shown), read


@pytest.mark.parametrize(
    ("message", "text"),
    [
        ("asset @tex/[v2](final).exr@ not found", r"asset @tex/\[v2\](final).exr@ not found"),
        ("layer {0}.usda, dictionary {a: 1}", "layer {{0}}.usda, dictionary {{a: 1}}"),
        ('purposes ["full", "allPurpose"]', 'purposes ["full", "allPurpose"]'),
        ("C:\\shots\\[010](1) {2}", "C:\\\\shots\\\\\\[010\\](1) {{2}}"),
    ],
)
def test_sarif_messages_hold_no_placeholder_or_link_a_viewer_would_fill(
    message: str, text: str
) -> None:
    """A message quotes asset paths, layer names and values: {0} and [text](1)
    in them are shown as written, not filled from arguments or linked."""
    finding = Finding("SE003", "d", Severity.ERROR, message, Location("a.usda", "/R", "a.usda", 1))
    failed = FileResult("b.usda", status="error", error=message)
    report = Report((FileResult("a.usda", findings=(finding,)), failed))
    run = report_to_sarif(report, FormatOptions(), Path.cwd())["runs"][0]
    (result,) = run["results"]
    (notification,) = run["invocations"][0]["toolExecutionNotifications"]
    for written in (result["message"]["text"], notification["message"]["text"]):
        assert written == text
        assert _as_a_viewer_shows(written) == (message, [])
