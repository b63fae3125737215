"""examples/github-workflow-sharded.yml parses, runs commands and options the
CLI accepts, and does what it says: N shard jobs and a merge job that uploads
the SARIF of all the files and gates like one check."""

from __future__ import annotations

import glob
import json
import re
import shlex
import shutil
from collections.abc import Iterator
from pathlib import Path

import click
import pytest
from click.testing import CliRunner

from usdrender_lint import __version__
from usdrender_lint.cli import cli

yaml = pytest.importorskip("yaml")  # PyYAML comes with pre-commit

REPO = Path(__file__).resolve().parents[2]
WORKFLOW = REPO / "examples" / "github-workflow-sharded.yml"


@pytest.fixture(scope="module")
def workflow() -> dict:
    return yaml.safe_load(WORKFLOW.read_text(encoding="utf-8"))


def _commands(job: dict, **matrix: object) -> Iterator[list[str]]:
    """The ``usdrender-lint`` command lines of a job's steps, with the matrix
    expressions replaced by ``matrix``'s values."""
    for step in job["steps"]:
        for line in step.get("run", "").splitlines():
            line = re.sub(r"\$\{\{\s*matrix\.(\w+)\s*\}\}", lambda m: str(matrix[m.group(1)]), line)
            words = shlex.split(line, comments=True)
            if words[:1] == ["usdrender-lint"]:
                yield words[1:]


def _shards(workflow: dict) -> list[int]:
    return workflow["jobs"]["lint"]["strategy"]["matrix"]["shard"]


def test_the_matrix_and_the_shard_option_agree(workflow: dict) -> None:
    shards = _shards(workflow)
    assert shards == list(range(1, len(shards) + 1)) and len(shards) > 1
    [check] = list(_commands(workflow["jobs"]["lint"], shard=1))
    assert check[check.index("--shard") + 1] == f"1/{len(shards)}"
    assert workflow["jobs"]["merge"]["needs"] == "lint"
    triggers = workflow.get("on", workflow.get(True))  # YAML 1.1 reads `on` as true
    assert "pull_request" in triggers
    assert workflow["permissions"]["security-events"] == "write"
    for job in workflow["jobs"].values():
        installs = [s["run"] for s in job["steps"] if "pip install" in s.get("run", "")]
        # Until the package is on an index, the release tag the docs name.
        assert installs == [
            'python -m pip install "git+${{ env.USDRENDER_LINT_GIT }}@v' + __version__ + '"'
        ]


def test_every_command_parses_with_the_real_cli(workflow: dict) -> None:
    commands = [
        *_commands(workflow["jobs"]["lint"], shard=2),
        *_commands(workflow["jobs"]["merge"]),
    ]
    assert [c[0] for c in commands] == ["check", "merge", "merge"]
    for args in commands:
        try:
            # Parses and validates every option and value, runs nothing.
            cli.commands[args[0]].make_context(args[0], args[1:])
        except click.UsageError as exc:
            pytest.fail(f"usdrender-lint {shlex.join(args)}: {exc.format_message()}")


def test_the_artifacts_flow_from_the_shards_to_the_merge(workflow: dict) -> None:
    lint, merge = workflow["jobs"]["lint"], workflow["jobs"]["merge"]
    [check] = list(_commands(lint, shard=3))
    [upload] = [s for s in lint["steps"] if s.get("uses", "").startswith("actions/upload-artifact")]
    uploaded = re.sub(r"\$\{\{\s*matrix\.shard\s*\}\}", "3", upload["with"]["path"])
    assert uploaded == check[check.index("--output") + 1] == "report-3.json"
    [download] = [
        s for s in merge["steps"] if s.get("uses", "").startswith("actions/download-artifact")
    ]
    pattern = download["with"]["pattern"].replace("*", "3")
    assert re.sub(r"\$\{\{.*?\}\}", "3", upload["with"]["name"]) == pattern
    [cache] = [s for s in lint["steps"] if s.get("uses", "").startswith("actions/cache")]
    assert cache["with"]["path"] == ".usdrender_lint_cache"
    sarif_run = next(c for c in _commands(merge) if "sarif" in c)
    [sarif_upload] = [s for s in merge["steps"] if "upload-sarif" in s.get("uses", "")]
    assert sarif_upload["with"]["sarif_file"] == sarif_run[sarif_run.index("--output") + 1]


def test_the_jobs_lint_a_checkout_like_one_check(
    workflow: dict, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Run each shard's command, hand the reports over as the artifacts would,
    run the merge job's commands: the SARIF holds every finding one unsharded
    check finds, and the gate fails on the broken shot."""
    for name in ("broken_shot", "clean_shot"):
        shutil.copytree(REPO / "examples" / name, tmp_path / name)
    monkeypatch.chdir(tmp_path)
    for shard in _shards(workflow):
        [check] = list(_commands(workflow["jobs"]["lint"], shard=shard))
        result = CliRunner().invoke(cli, check)
        assert result.exit_code == 0, result.output  # records only, never gates
    reports = tmp_path / "reports"
    reports.mkdir()
    for report in tmp_path.glob("report-*.json"):
        report.rename(reports / report.name)
    one_run = CliRunner().invoke(cli, ["check", "--format", "sarif", "--no-cache", "."])
    sarif_run, gate = list(_commands(workflow["jobs"]["merge"]))
    expand = [w for a in sarif_run for w in (sorted(glob.glob(a)) if "*" in a else [a])]
    recorded = CliRunner().invoke(cli, expand)
    assert recorded.exit_code == 0, recorded.output
    merged = json.loads((tmp_path / "results.sarif").read_text())
    assert merged["runs"][0]["results"] == json.loads(one_run.stdout)["runs"][0]["results"]
    assert merged["runs"][0]["results"]
    gated = CliRunner().invoke(cli, [w for a in gate for w in (sorted(glob.glob(a)) or [a])])
    assert gated.exit_code == 1, gated.output
    assert gated.stdout.startswith("::error ")
