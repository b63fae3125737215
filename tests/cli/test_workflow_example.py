"""examples/github-workflow.yml runs commands the CLI accepts, and they work."""

from __future__ import annotations

import json
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
WORKFLOW = REPO / "examples" / "github-workflow.yml"


@pytest.fixture(scope="module")
def workflow() -> dict:
    return yaml.safe_load(WORKFLOW.read_text(encoding="utf-8"))


def _steps(workflow: dict) -> list[dict]:
    [job] = workflow["jobs"].values()
    return job["steps"]


def _lint_commands(workflow: dict) -> Iterator[list[str]]:
    """The arguments of every ``usdrender-lint`` command line the steps run."""
    for step in _steps(workflow):
        for line in step.get("run", "").splitlines():
            words = shlex.split(line, comments=True)
            if words[:1] == ["usdrender-lint"]:
                yield words[1:]


def _format_of(args: list[str]) -> str:
    return args[args.index("--format") + 1]


def test_the_workflow_runs_on_pull_requests_with_the_permissions_it_needs(
    workflow: dict,
) -> None:
    triggers = workflow.get("on", workflow.get(True))  # YAML 1.1 reads `on` as true
    assert "pull_request" in triggers
    assert workflow["permissions"]["security-events"] == "write"
    installs = [s["run"] for s in _steps(workflow) if "pip install" in s.get("run", "")]
    # From a tag of the Git repository (the package is on no index yet).
    assert installs == [
        'python -m pip install "git+${{ env.USDRENDER_LINT_GIT }}@v' + __version__ + '"'
    ]
    assert workflow["env"]["USDRENDER_LINT_GIT"].endswith(".git")


def test_every_lint_command_parses_with_the_real_cli(workflow: dict) -> None:
    commands = list(_lint_commands(workflow))
    assert {_format_of(args) for args in commands} == {"sarif", "github"}
    check = cli.commands["check"]
    for args in commands:
        assert args[0] == "check"
        try:
            # Parses and validates every option and value, runs nothing.
            check.make_context("check", args[1:])
        except click.UsageError as exc:
            pytest.fail(f"usdrender-lint {shlex.join(args)}: {exc.format_message()}")


def test_the_uploaded_file_is_the_one_the_sarif_run_writes(workflow: dict) -> None:
    [sarif_run] = [a for a in _lint_commands(workflow) if _format_of(a) == "sarif"]
    written = sarif_run[sarif_run.index("--output") + 1]
    uploads = [s for s in _steps(workflow) if "upload-sarif" in s.get("uses", "")]
    assert [s["uses"].split("@")[0] for s in uploads] == ["github/codeql-action/upload-sarif"]
    assert uploads[0]["with"]["sarif_file"] == written
    steps = _steps(workflow)
    assert steps.index(uploads[0]) > next(
        i for i, s in enumerate(steps) if "--format sarif" in s.get("run", "")
    )


def test_the_commands_work_on_a_checkout_with_a_broken_shot(
    workflow: dict, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    shutil.copytree(REPO / "examples" / "broken_shot", tmp_path / "broken_shot")
    monkeypatch.chdir(tmp_path)
    sarif_run, annotate_run = sorted(_lint_commands(workflow), key=_format_of, reverse=True)

    recorded = CliRunner().invoke(cli, sarif_run)
    assert recorded.exit_code == 0, recorded.output  # records only, never gates
    sarif = json.loads((tmp_path / "results.sarif").read_text(encoding="utf-8"))
    assert sarif["version"] == "2.1.0"
    assert sarif["runs"][0]["results"]

    gated = CliRunner().invoke(cli, annotate_run)
    assert gated.exit_code == 1, gated.output
    assert gated.stdout.startswith("::error ")
