"""A layer behind a symbolic link is named as the user named it, in every
format alike: relative to the working directory, never the link's target."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.formatters.github import escape_property

REPO = Path(__file__).parents[2]
SHOT = REPO / "examples" / "broken_shot"
FORMATS = ("text", "full", "github", "gitlab", "junit", "sarif", "json", "html")


@pytest.fixture
def linked(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """``repo/shots`` links to ``vault-target/shots`` outside the working directory
    ``repo``; ``repo/gone.usda`` links to a file that does not exist."""
    shutil.copytree(SHOT, tmp_path / "vault-target" / "shots")
    (tmp_path / "repo").mkdir()
    os.symlink("../vault-target/shots", tmp_path / "repo" / "shots")
    os.symlink("../vault-target/none.usda", tmp_path / "repo" / "gone.usda")
    monkeypatch.chdir(tmp_path / "repo")
    return tmp_path


def _check(output_format: str) -> str:
    result = CliRunner().invoke(
        cli,
        ["check", "--isolated", "--jobs", "1", "--format", output_format, "shots", "gone.usda"],
    )
    assert result.exit_code == 2, result.output
    return result.stdout


@pytest.mark.parametrize("output_format", FORMATS)
def test_every_format_names_a_linked_layer_by_its_link(linked, output_format) -> None:
    output = _check(output_format)
    assert "shots/shot.usda" in output
    # SARIF's root, the working directory, is the one absolute path.
    shown = output.replace(f"file://{linked}/repo/", "")
    assert "vault-target" not in shown


def test_formats_name_the_same_files_as_json(linked) -> None:
    document = json.loads(_check("json"))
    layers = {f["layer"] for file in document["files"] for f in file["findings"]} - {None}
    assert layers and all(layer.startswith("shots/") for layer in layers)
    github = _check("github")
    gitlab = json.loads(_check("gitlab"))
    sarif = json.loads(_check("sarif"))
    uris = {
        location["physicalLocation"]["artifactLocation"]["uri"]
        for result in sarif["runs"][0]["results"]
        for location in result.get("locations", ())
        if "physicalLocation" in location
    }
    assert {issue["location"]["path"] for issue in gitlab} == layers | {"gone.usda"}
    assert uris == layers
    # An annotation's file is absolute (the runner shows it relative to the
    # repository), named by the link too.
    repo = linked / "repo"
    assert all(f"file={escape_property(str(repo / layer))}," in github for layer in layers)
    notice = sarif["runs"][0]["invocations"][0]["toolExecutionNotifications"]
    assert [n["locations"][0]["physicalLocation"]["artifactLocation"] for n in notice] == [
        {"uri": "gone.usda", "uriBaseId": "SRCROOT"}
    ]


def test_gitlab_fingerprints_do_not_change_with_the_checkout(
    linked, tmp_path_factory, monkeypatch
) -> None:
    first = [issue["fingerprint"] for issue in json.loads(_check("gitlab"))]
    elsewhere = tmp_path_factory.mktemp("elsewhere") / "copy"
    shutil.copytree(linked, elsewhere, symlinks=True)
    monkeypatch.chdir(elsewhere / "repo")
    assert [issue["fingerprint"] for issue in json.loads(_check("gitlab"))] == first
