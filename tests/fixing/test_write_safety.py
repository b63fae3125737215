"""Writing fixed layers: never over an edit made meanwhile, owner, group and
mode kept, hard links never split, .usdz refused with a pointer to --fix-to."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from click.testing import CliRunner
from pxr import UsdRender

from usdrender_lint.api import Diagnostic, Fix, Rule, Severity
from usdrender_lint.cli import cli
from usdrender_lint.engine import Linter
from usdrender_lint.fixing import FixOptions, fix_files

SHOT = """#usda 1.0

def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform token aspectRatioConformPolicy = "cropaperture"
    }
}
"""
FIXED = SHOT.replace('"cropaperture"', '"cropAperture"')


def check(*args: str):
    base = ["check", "--isolated", "-j", "1", "--timeout", "0", "--select", "SE006"]
    result = CliRunner().invoke(cli, [*base, "--format", "json", *args])
    return result, json.loads(result.stdout) if result.stdout.startswith("{") else None


def test_a_file_edited_while_fixing_is_left_alone(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(SHOT, encoding="utf-8")
    someone_else = SHOT.replace("def Scope", "# edited by someone else\ndef Scope")

    class EditsTheFileMeanwhile(Rule):
        """A rule for the test whose fix also changes the file on disk, as
        another program would while --fix runs.

        ## Fix safety
        Safe.
        """

        code = "TW001"
        name = "edits-the-file"
        severity = Severity.ERROR
        prim_types = (UsdRender.Settings,)
        fix_safety = "safe"

        def check_prim(self, prim, ctx):
            attr = prim.GetAttribute("aspectRatioConformPolicy")
            if attr.Get() == "cropaperture":

                def apply(stage):
                    shot.write_text(someone_else, encoding="utf-8")
                    stage.GetAttributeAtPath(attr.GetPath()).Set("cropAperture")

                yield Diagnostic(
                    message="slip", at=attr, fix=Fix(description="fix", safe=True, apply=apply)
                )

    result = fix_files(Linter([EditsTheFileMeanwhile()]), [str(shot)], FixOptions())
    assert shot.read_text(encoding="utf-8") == someone_else  # their edit is kept
    (outcome,) = result.outcomes
    assert not outcome.applied and "changed on disk while fixing" in outcome.reason
    assert result.errors and "shot.usda: not written" in result.errors[0]


def test_the_run_exits_2_when_a_file_could_not_be_written(tmp_path: Path, monkeypatch) -> None:
    from usdrender_lint.layers import writing

    shot = tmp_path / "shot.usda"
    shot.write_text(SHOT, encoding="utf-8")

    def changed(state):
        raise writing.ChangedOnDisk("it changed on disk while fixing; it was left as it is")

    monkeypatch.setattr(writing.DiskState, "check_unchanged", changed)
    result, document = check("--fix", str(shot))
    assert result.exit_code == 2
    assert "shot.usda: not written: it changed on disk" in result.stderr
    assert shot.read_text(encoding="utf-8") == SHOT
    assert document["fixes"][0]["applied"] is False


@pytest.mark.skipif(os.geteuid() != 0, reason="only root may give a file to another user")
def test_owner_group_and_mode_are_kept(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(SHOT, encoding="utf-8")
    os.chown(shot, 4321, 8765)
    shot.chmod(0o664)
    result, _ = check("--fix", str(shot))
    assert result.exit_code == 0, result.output
    assert shot.read_text(encoding="utf-8") == FIXED
    stat = shot.stat()
    assert (stat.st_uid, stat.st_gid, stat.st_mode & 0o777) == (4321, 8765, 0o664)


def test_keep_owner_keeps_the_group_when_the_owner_cannot_be_set(
    tmp_path: Path, monkeypatch
) -> None:
    from usdrender_lint.layers import writing

    path = tmp_path / "f"
    path.write_text("x", encoding="utf-8")
    calls = []

    def chown(target, uid, gid):
        calls.append((uid, gid))
        if uid != -1:
            raise PermissionError("not the owner")

    monkeypatch.setattr(writing.os, "chown", chown)
    writing.keep_owner(path, 4321, 8765)
    assert calls == [(4321, 8765), (-1, 8765)]


def test_a_hard_linked_file_is_not_split(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(SHOT, encoding="utf-8")
    link = tmp_path / "same_shot.usda"
    os.link(shot, link)
    result, document = check("--fix", str(shot))
    assert shot.read_text(encoding="utf-8") == SHOT
    assert os.path.samefile(shot, link)
    (fix,) = document["fixes"]
    assert not fix["applied"] and "2 hard links" in fix["reason"]
    assert "--fix-to" in fix["reason"]


def test_the_backup_a_killed_write_left_is_named(tmp_path: Path) -> None:
    """A fix killed while it wrote (kill -9, a power cut)
    leaves its backup hard link beside the file: every later --fix refused the
    file for its "2 hard links" without saying which, or why."""
    shot = tmp_path / "shot.usda"
    shot.write_text(SHOT, encoding="utf-8")
    backup = tmp_path / ".shot.usda.1fdc6802.orig"
    os.link(shot, backup)
    result, document = check("--fix", str(shot))
    (fix,) = document["fixes"]
    assert not fix["applied"] and ".shot.usda.1fdc6802.orig" in fix["reason"]
    assert "remove that file" in fix["reason"]
    backup.unlink()
    check("--fix", str(shot))
    assert shot.read_text(encoding="utf-8") == FIXED


def test_a_usdz_is_refused_with_a_pointer_to_fix_to(tmp_path: Path) -> None:
    from pxr import Sdf, UsdUtils

    source = tmp_path / "shot.usda"
    source.write_text(SHOT, encoding="utf-8")
    package = tmp_path / "shot.usdz"
    assert UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(str(source)), str(package))
    result, document = check("--fix", str(package))
    (fix,) = document["fixes"]
    assert ".usdz" in fix["reason"] and "--fix-to" in fix["reason"]


@pytest.mark.parametrize("timeout", ["0", "60"], ids=["in-process", "worker"])
def test_a_layer_the_configuration_excludes_is_left_alone(
    tmp_path: Path, monkeypatch, timeout: str
) -> None:
    """As ruff never edits an excluded file: a vendored sublayer the shot
    composes keeps its text; named itself, it is fixed."""
    (tmp_path / "vendor").mkdir()
    base = tmp_path / "vendor" / "base.usda"
    base.write_text(SHOT, encoding="utf-8")
    shot = tmp_path / "shot.usda"
    shot.write_text("#usda 1.0\n(\n    subLayers = [@./vendor/base.usda@]\n)\n", encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    excluded = ["--extend-exclude", "vendor/", "--timeout", timeout]
    result, document = check(*excluded, "--fix", "shot.usda")
    assert base.read_text(encoding="utf-8") == SHOT
    (fix,) = document["fixes"]
    assert not fix["applied"]
    assert fix["reason"].startswith("vendor/base.usda is left out of linting by the configuration")
    result, document = check(*excluded, "--diff", "shot.usda")
    assert "+++" not in result.stdout
    check(*excluded, "--fix", "vendor/base.usda")
    assert base.read_text(encoding="utf-8") == FIXED
