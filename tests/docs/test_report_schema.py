"""docs/report-schema.json describes the JSON report the command writes:
findings, statistics, fixes and a file that could not be linted."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli

jsonschema = pytest.importorskip("jsonschema")

REPO = Path(__file__).resolve().parents[2]
SCHEMA = json.loads((REPO / "docs" / "report-schema.json").read_text(encoding="utf-8"))


def _report(*args: str) -> dict:
    result = CliRunner().invoke(cli, ["check", "--format", "json", "--jobs", "1", *args])
    assert result.exit_code in (0, 1, 2), result.output
    return json.loads(result.stdout) if "--output" not in args else {}


def test_the_examples_report_matches_the_schema(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(REPO)
    document = _report("--statistics", "examples/", "examples/no-such-file.usda")
    jsonschema.validate(document, SCHEMA)
    statuses = {f["status"] for f in document["files"]}
    assert statuses == {"linted", "error"} and document["statistics"]
    findings = [f for file in document["files"] for f in file["findings"]]
    assert any(f["fix"] for f in findings) and any(f["line"] for f in findings)


def test_a_fixing_report_matches_the_schema(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    shutil.copytree(REPO / "examples" / "broken_shot", tmp_path / "shot")
    monkeypatch.chdir(tmp_path)
    # --diff prints the patch on stdout; the report goes to --output.
    _report("--diff", "--output", "report.json", "shot")
    document = json.loads((tmp_path / "report.json").read_text(encoding="utf-8"))
    jsonschema.validate(document, SCHEMA)
    assert document["fixes"]


def test_the_schema_requires_what_a_finding_carries() -> None:
    bad = {
        "schema_version": 1,
        "tool": {"name": "usdrender-lint", "version": "0"},
        "files": [
            {"file": "a.usda", "status": "linted", "error": None, "findings": [{"code": "CA004"}]}
        ],
        "summary": {
            "files": 1,
            "findings": 1,
            "by_severity": {"error": 1, "warning": 0, "info": 0},
        },
    }
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, SCHEMA)


def test_a_shard_report_matches_the_schema(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(REPO)
    document = _report("--shard", "2/3", "examples/")
    jsonschema.validate(document, SCHEMA)
    assert document["shard"] == {"index": 2, "count": 3}
    assert document["working_directory"] == str(REPO)
    for bad in ({"index": 0, "count": 3}, {"index": 1}, "2/3"):
        with pytest.raises(jsonschema.ValidationError):
            jsonschema.validate({**document, "shard": bad}, SCHEMA)


def _json_example(page: str) -> dict:
    text = (REPO / "docs" / "reference" / page).read_text(encoding="utf-8")
    return json.loads(text.split("```json\n", 1)[1].split("```", 1)[0])


def test_the_json_reference_example_is_what_check_prints(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(REPO)
    shown = _json_example("json-report.md")
    printed = _report("--no-cache", "--select", "CA004", "examples/broken_shot/shot.usda")
    jsonschema.validate(shown, SCHEMA)
    # The digest changes with every rule: the page shows one of the same form.
    assert len(shown.pop("configuration")) == len(printed.pop("configuration")) == 32
    assert shown == printed


def _shown_in(shown: object, printed: object) -> bool:
    """Whether an abridged example says only what ``printed`` holds: its keys
    (but "...") with the same values, each item of a list among the printed ones."""
    if isinstance(shown, dict):
        return isinstance(printed, dict) and all(
            key in printed and _shown_in(value, printed[key])
            for key, value in shown.items()
            if key != "..."
        )
    if isinstance(shown, list) and any(isinstance(item, dict) for item in shown):
        return isinstance(printed, list) and all(
            any(_shown_in(item, candidate) for candidate in printed) for item in shown
        )
    return shown == printed


def test_the_spec_json_reference_example_is_what_spec_prints(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.chdir(REPO)
    run = CliRunner().invoke(
        cli, ["spec", "--format", "json", "--jobs", "1", "examples/framing_shot/shot.usda"]
    )
    assert _shown_in(_json_example("spec-json.md"), json.loads(run.stdout))
