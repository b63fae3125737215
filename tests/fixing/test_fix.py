"""--fix, --diff and --fix-to: the right layer, atomic format-keeping writes,
refusals with reasons (read-only, outside the layer stack), comments kept, and
overrides that give the fixed result when their layer roots the stage."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner
from fix_support import check, codes, spec_fields, write
from pxr import Sdf, Usd, UsdRender

from usdrender_lint import fixing as fixer
from usdrender_lint.api import Diagnostic, Fix, Rule, Severity
from usdrender_lint.api.resolve import composed_value
from usdrender_lint.cli import cli
from usdrender_lint.engine import Linter
from usdrender_lint.fixing import session
from usdrender_lint.fixing.diff import patch
from usdrender_lint.layers import writing
from usdrender_lint.layers.usda_text import comment_lines
from usdrender_lint.registry import build_registry

FIXTURES = Path(__file__).parents[1] / "rules"

#: SE006 with a case slip (safe fix) and SE007 (safe fix that removes an opinion).
SHOT = """#usda 1.0

def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform token aspectRatioConformPolicy = "cropaperture"
        uniform bool instantaneousShutter = 1
        int2 resolution = (1920, 1080)
    }
}
"""
POLICY = "/Render/Settings.aspectRatioConformPolicy"


def value(path: Path, attr: str = POLICY):
    stage = Usd.Stage.Open(str(path))
    return stage.GetAttributeAtPath(attr).Get()


def reasons(document: dict) -> list[str]:
    return [fix["reason"] for fix in document["fixes"] if not fix["applied"]]


# -- the basic path -------------------------------------------------------------------


def test_fix_edits_the_file_and_reports_what_remains(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    result, document = check("--select", "SE006,SE007", "--fix", str(shot))
    assert result.exit_code == 0, result.output  # nothing remains at error level
    assert value(shot) == "cropAperture"
    stage = Usd.Stage.Open(str(shot))
    settings = stage.GetPrimAtPath("/Render/Settings")
    assert not settings.GetAttribute("instantaneousShutter").HasAuthoredValue()
    assert settings.GetAttribute("disableMotionBlur").Get() is True
    assert codes(document) == []
    applied = {(fix["code"], fix["path"]) for fix in document["fixes"] if fix["applied"]}
    assert applied == {("SE006", POLICY), ("SE007", "/Render/Settings.instantaneousShutter")}
    assert all(fix["layer"].endswith("shot.usda") for fix in document["fixes"])


def test_text_report_lists_and_counts_applied_fixes(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    result = CliRunner().invoke(
        cli, ["check", "--isolated", "-j", "1", "--select", "SE006", "--fix", str(shot)]
    )
    assert "1 fix applied" in result.output
    assert f'shot.usda: fixed SE006 {POLICY}: set to "cropAperture"' in result.output


def test_second_fix_changes_nothing(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    check("--select", "SE006,SE007", "--fix", str(shot))
    fixed = shot.read_bytes()
    result, document = check("--select", "SE006,SE007", "--fix", str(shot))
    assert result.exit_code == 0
    assert shot.read_bytes() == fixed
    assert document["fixes"] == []


def test_unsafe_fixes_need_the_flag(tmp_path: Path) -> None:
    # SE003's swap of an inverted data window is unsafe.
    window_line = "uniform float4 dataWindowNDC = (0.8, 0, 0.2, 1)\n        "
    text = SHOT.replace("int2 resolution", window_line + "int2 resolution")
    shot = write(tmp_path / "shot.usda", text)
    window = "/Render/Settings.dataWindowNDC"
    result, document = check("--select", "SE003", "--fix", str(shot))
    assert result.exit_code == 1
    assert document["fixes"] == [] and codes(document) == ["SE003"]
    result, document = check("--select", "SE003", "--fix", "--unsafe-fixes", str(shot))
    assert result.exit_code == 0, result.output
    assert tuple(value(shot, window)) == pytest.approx((0.2, 0, 0.8, 1))
    # The catalog's spelling, --fix --unsafe, is the same flag.
    write(tmp_path / "shot.usda", text)
    result, _ = check("--select", "SE003", "--fix", "--unsafe", str(shot))
    assert result.exit_code == 0, result.output
    assert tuple(value(shot, window)) == pytest.approx((0.2, 0, 0.8, 1))


def test_the_fix_goes_to_the_layer_of_the_strongest_opinion(tmp_path: Path) -> None:
    write(tmp_path / "weak.usda", SHOT.replace('"cropaperture"', '"expandAperture"'))
    strong = write(tmp_path / "strong.usda", SHOT)
    root = write(
        tmp_path / "root.usda", "#usda 1.0\n(\n    subLayers = [@strong.usda@, @weak.usda@]\n)\n"
    )
    weak_before = (tmp_path / "weak.usda").read_bytes()
    result, document = check("--select", "SE006", "--fix", str(root))
    assert result.exit_code == 0, result.output
    assert value(strong) == "cropAperture"
    assert (tmp_path / "weak.usda").read_bytes() == weak_before
    assert "aspectRatioConformPolicy" not in root.read_text()
    assert document["fixes"][0]["layer"].endswith("strong.usda")


def test_per_path_ignored_findings_are_not_fixed(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    config = write(tmp_path / "lint.toml", '[per-path-ignores]\n"shot.usda" = ["SE006"]\n')
    result = CliRunner().invoke(
        cli, ["check", "-j", "1", "--config", str(config), "--select", "SE006", "--fix", str(shot)]
    )
    assert result.exit_code == 0, result.output
    assert value(shot) == "cropaperture"


# -- nothing is lost ------------------------------------------------------------------


def test_a_failed_write_leaves_the_original_intact(tmp_path: Path, monkeypatch) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    original = shot.read_bytes()

    def full_disk(descriptor):  # the temporary file is written, then the disk is full
        raise OSError("disk full")

    monkeypatch.setattr(writing.os, "fsync", full_disk)
    result, document = check("--select", "SE006", "--fix", str(shot))
    assert shot.read_bytes() == original
    assert sorted(p.name for p in tmp_path.iterdir()) == ["shot.usda"]  # no temporary left
    assert result.exit_code == 2  # a file the tool could not write
    assert "shot.usda: writing failed: disk full" in result.stderr
    assert codes(document) == ["SE006"]
    (reason,) = reasons(document)
    assert "disk full" in reason and "shot.usda" in reason
    assert document["fixes"][0]["applied"] is False


def test_a_usdc_stays_a_usdc(tmp_path: Path) -> None:
    source = Sdf.Layer.CreateAnonymous(".usda")
    source.ImportFromString(SHOT)
    crate = tmp_path / "shot.usdc"
    source.Export(str(crate))
    result, _ = check("--select", "SE006", "--fix", str(crate))
    assert result.exit_code == 0, result.output
    assert crate.read_bytes().startswith(b"PXR-USDC")
    assert value(crate) == "cropAperture"


@pytest.mark.parametrize("encoding", ["usda", "usdc"])
def test_a_usd_keeps_its_encoding(tmp_path: Path, encoding: str) -> None:
    source = Sdf.Layer.CreateAnonymous(".usda")
    source.ImportFromString(SHOT)
    shot = tmp_path / "shot.usd"
    source.Export(str(shot), args={"format": encoding})
    result, _ = check("--select", "SE006", "--fix", str(shot))
    assert result.exit_code == 0, result.output
    assert shot.read_bytes().startswith(b"PXR-USDC") == (encoding == "usdc")
    assert value(shot) == "cropAperture"


def _old_crate(path: Path) -> None:
    """SHOT as a crate of version 0.7.0: Sdf reads the version new files get
    once per process, so another process writes it."""
    code = (
        "import sys; from pxr import Sdf; layer = Sdf.Layer.CreateAnonymous('.usda'); "
        "layer.ImportFromString(sys.argv[1]); layer.Export(sys.argv[2], args={'format': 'usdc'})"
    )
    env = dict(os.environ, USD_WRITE_NEW_USDC_FILES_AS_VERSION="0.7.0")
    subprocess.run([sys.executable, "-c", code, SHOT, str(path)], env=env, check=True)


@pytest.mark.parametrize("name", ["shot.usdc", "shot.usd"])
def test_a_crate_keeps_its_version(tmp_path: Path, monkeypatch, name: str) -> None:
    monkeypatch.setenv("PXR_USDC_EMIT_DEPRECATION_WARNINGS", "0")
    crate = tmp_path / name
    _old_crate(crate)
    assert crate.read_bytes()[8:11] == bytes([0, 7, 0])
    result, _ = check("--select", "SE006,SE007", "--fix", str(crate))
    assert result.exit_code == 0, result.output
    # An older USD, which reads 0.7.0 but not 0.8.0, still reads the fixed file.
    assert crate.read_bytes()[8:11] == bytes([0, 7, 0])
    assert value(crate) == "cropAperture"
    stage = Usd.Stage.Open(str(crate))
    shutter = stage.GetAttributeAtPath("/Render/Settings.instantaneousShutter")
    assert not shutter.HasAuthoredValue()  # SE007's fix, a removal, is kept too


def test_a_fix_keeps_the_file_permissions(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    shot.chmod(0o640)
    check("--select", "SE006", "--fix", str(shot))
    assert value(shot) == "cropAperture"
    assert stat.S_IMODE(shot.stat().st_mode) == 0o640


def test_a_linked_layer_is_fixed_through_the_link(tmp_path: Path) -> None:
    real = write(tmp_path / "real.usda", SHOT)
    link = tmp_path / "shot.usda"
    link.symlink_to(real.name)
    result, _ = check("--select", "SE006", "--fix", str(link))
    assert result.exit_code == 0, result.output
    assert link.is_symlink()
    assert value(real) == "cropAperture"


@pytest.mark.parametrize(
    ("code", "fixture"),
    [
        ("SE016", "SE016_attribute_type_mismatch/fail_types.usda"),
        ("CA006", "CA006_aspect_ratio_mismatch_implicit_conform/fail_mismatch.usda"),
        ("ST008", "ST008_render_prim_outside_render_scope/fail_outside.usda"),
    ],
)
def test_only_the_fixed_opinions_change(tmp_path: Path, code: str, fixture: str) -> None:
    source = FIXTURES / fixture
    shot = write(tmp_path / "shot.usda", source.read_text(encoding="utf-8"))
    before = spec_fields(Usd.Stage.Open(str(shot)).Flatten())
    extra = ("--unsafe-fixes",) if code == "ST008" else ()
    _, document = check("--select", code, "--fix", "--fix-drop-comments", *extra, str(shot))
    after = spec_fields(Usd.Stage.Open(str(shot)).Flatten())
    fixed = {fix["path"] for fix in document["fixes"] if fix["applied"]}
    assert fixed
    changed = {p for p in before.keys() | after.keys() if before.get(p) != after.get(p)}
    if code == "ST008":
        # A move changes the moved prims, everything below them, the targets
        # that pointed at them and renderSettingsPrimPath (the pseudo-root's
        # field) when it names one; nothing else.
        moved = [Sdf.Path(p) for p in fixed]
        outside = {p for p in changed if not any(Sdf.Path(p).HasPrefix(m) for m in moved)}
        assert all(p.startswith("/Render") for p in outside - {"/"}), outside
        assert before["/"]["renderSettingsPrimPath"] == "'/Settings'"
        assert after["/"]["renderSettingsPrimPath"] == "'/Render/Settings'"
        return
    # Only properties change, and only on the prims whose findings were fixed.
    assert changed and all(Sdf.Path(p).IsPropertyPath() for p in changed), changed
    fixed_prims = {Sdf.Path(p).GetPrimPath() for p in fixed}
    assert {Sdf.Path(p).GetPrimPath() for p in changed} <= fixed_prims


# -- refusals -------------------------------------------------------------------------


def test_a_read_only_layer_is_not_edited(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    shot.chmod(0o444)
    try:
        result, document = check("--select", "SE006", "--fix", str(shot))
    finally:
        shot.chmod(0o644)
    assert result.exit_code == 1
    assert shot.read_text(encoding="utf-8") == SHOT
    (reason,) = reasons(document)
    assert "read-only" in reason
    assert "1 fix not applied (SE006): " in result.stderr and "read-only" in result.stderr


def test_a_layer_outside_the_layer_stack_is_not_edited(tmp_path: Path) -> None:
    # The bad token lives in a referenced layer: editing it would change every
    # other stage that references it, so --fix refuses (--fix-to can override).
    asset = write(tmp_path / "asset.usda", SHOT.replace('def Scope "Render"', 'def Scope "R"'))
    asset_before = asset.read_bytes()
    shot = write(
        tmp_path / "shot.usda",
        '#usda 1.0\n\ndef Scope "Render" (\n    references = @asset.usda@</R>\n)\n{\n}\n',
    )
    shot_before = shot.read_bytes()
    result, document = check("--select", "SE006", "--fix", str(shot))
    assert result.exit_code == 1
    assert asset.read_bytes() == asset_before and shot.read_bytes() == shot_before
    (reason,) = reasons(document)
    assert "outside the stage's layer stack" in reason and "--fix-to" in reason
    assert "--fix-to" in result.stderr
    # --fix-to overrides it from the stage, leaving both files alone.
    overrides = tmp_path / "fixes.usda"
    result, document = check("--select", "SE006", "--fix-to", str(overrides), str(shot))
    assert result.exit_code == 0, result.output
    assert asset.read_bytes() == asset_before and shot.read_bytes() == shot_before
    layer = Sdf.Layer.OpenAsAnonymous(str(overrides))
    assert layer.GetAttributeAtPath(POLICY).default == "cropAperture"


def test_a_usda_with_comments_is_fixed_keeping_them(tmp_path: Path) -> None:
    text = SHOT.replace("def Scope", "# shot 42, approved\ndef Scope")
    shot = write(tmp_path / "shot.usda", text)
    result, document = check("--select", "SE006", "--fix", str(shot))
    assert result.exit_code == 0, result.output
    assert value(shot) == "cropAperture"
    assert shot.read_text(encoding="utf-8") == text.replace('"cropaperture"', '"cropAperture"')
    # --fix-drop-comments is accepted and changes nothing: comments are always kept.
    again = write(tmp_path / "again.usda", text)
    result, _ = check("--select", "SE006", "--fix", "--fix-drop-comments", str(again))
    assert result.exit_code == 0
    assert again.read_text(encoding="utf-8") == shot.read_text(encoding="utf-8")


def test_comment_lines_skip_the_header_strings_and_assets() -> None:
    text = (
        "#usda 1.0\n"
        '(\n    doc = "# not a comment // either"\n)\n'
        "# one\n"
        'def "A" {\n    asset a = @x#y@  // two\n    /* three\n    */\n}\n'
    )
    assert comment_lines(text) == [5, 7, 8]
    assert comment_lines('#usda 1.0\ndef Scope "A"\n{\n}\n') == []


def test_a_layer_in_a_usdz_package_is_not_edited(tmp_path: Path) -> None:
    source = write(tmp_path / "shot.usda", SHOT)
    package = tmp_path / "shot.usdz"
    from pxr import UsdUtils

    assert UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(str(source)), str(package))
    package_before = package.read_bytes()
    result, document = check("--select", "SE006", "--fix", str(package))
    assert result.exit_code == 1
    assert package.read_bytes() == package_before
    (reason,) = reasons(document)
    assert ".usdz" in reason


def test_fix_to_writes_the_fixes_of_a_layer_in_a_usdz_package(tmp_path: Path) -> None:
    """The in-memory fixes of a package's layer were not undone before the
    overrides were worked out: nothing was written for them and the report
    lost their findings, though the --fix-to stage still has them."""
    source = write(tmp_path / "settings.usda", SHOT)
    package = tmp_path / "settings.usdz"
    from pxr import UsdUtils

    assert UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(str(source)), str(package))
    # A member named in the package: its real path is no file of its own.
    shot = write(
        tmp_path / "shot.usda",
        "#usda 1.0\n(\n    subLayers = [@./settings.usdz[settings.usda]@]\n)\n",
    )
    overlay = tmp_path / "fixed.usda"
    result, document = check("--select", "SE006", "--fix-to", str(overlay), str(shot))
    assert result.exit_code == 0, result.output
    assert [(f["code"], f["applied"]) for f in document["fixes"]] == [("SE006", True)]
    assert value(overlay) == "cropAperture"
    assert codes(check("--select", "SE006", str(overlay))[1]) == []


# -- --diff ---------------------------------------------------------------------------


#: A sublayer two shots share: each shot's camera decides whether CA006 fixes it.
SHARED_SETTINGS = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel camera = </Cam>
        uniform int2 resolution = (1920, 1080)
        uniform token[] includedPurposes = ["render"]
    }
}
"""


@pytest.mark.parametrize("jobs", [["-j", "1", "--timeout", "0"], ["-j", "2"]])
def test_diff_of_stages_fixing_a_shared_layer_differently_is_one_patch(
    tmp_path: Path, monkeypatch, jobs: list[str]
) -> None:
    """Each stage's patch of the layer was printed, each from its file as read:
    the second did not apply after the first (patch, git apply)."""
    write(tmp_path / "settings.usda", SHARED_SETTINGS)
    shots = []
    for name, height in (("a", "20.25"), ("b", "24")):  # 16:9 (no CA006), 3:2
        shots.append(
            write(
                tmp_path / f"{name}.usda",
                "#usda 1.0\n(\n    subLayers = [@./settings.usda@]\n"
                '    renderSettingsPrimPath = "/Render/Settings"\n)\n'
                f'def Camera "Cam"\n{{\n    float horizontalAperture = 36\n'
                f"    float verticalAperture = {height}\n}}\n",
            )
        )
    monkeypatch.chdir(tmp_path)
    args = ["check", "--isolated", *jobs, "--select", "CA006,SE010"]
    diff = CliRunner().invoke(cli, [*args, "--diff", *map(str, shots)])
    assert diff.exit_code == 1, diff.output
    fixed = CliRunner().invoke(cli, [*args, "--fix", *map(str, shots)])
    assert fixed.exit_code == 0, fixed.output
    after = (tmp_path / "settings.usda").read_text(encoding="utf-8")
    assert "expandAperture" in after and '["default", "render"]' in after
    assert diff.stdout == patch("settings.usda", SHARED_SETTINGS, after)


def test_diff_prints_the_change_and_writes_nothing(tmp_path: Path, monkeypatch) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(
        cli, ["check", "--isolated", "-j", "1", "--select", "SE006", "--diff", str(shot)]
    )
    assert result.exit_code == 1  # a fix is pending
    assert shot.read_text(encoding="utf-8") == SHOT
    assert result.stdout.startswith("--- shot.usda\n+++ shot.usda\n")
    assert '-        uniform token aspectRatioConformPolicy = "cropaperture"' in result.stdout
    assert '+        uniform token aspectRatioConformPolicy = "cropAperture"' in result.stdout
    assert "1 fix would be applied" in result.stderr
    # The in-memory edit is gone: linting again in this process sees the file.
    _, document = check("--select", "SE006", str(shot))
    assert codes(document) == ["SE006"]


def test_diff_report_says_what_would_be_fixed_not_what_was(tmp_path: Path, monkeypatch) -> None:
    # --diff writes nothing: the report it writes to --output must not claim
    # "fixed" or "fixes applied" (it did, misleading whoever read the file).
    shot = write(tmp_path / "shot.usda", SHOT)
    monkeypatch.chdir(tmp_path)
    args = ["check", "--isolated", "-j", "1", "--select", "SE006", "--diff"]
    result = CliRunner().invoke(cli, [*args, "--output", "report.txt", str(shot)])
    assert result.exit_code == 1, result.output
    report = (tmp_path / "report.txt").read_text(encoding="utf-8")
    assert "shot.usda: would fix SE006 " in report
    assert report.rstrip().endswith("; 1 fix would be applied.")
    assert "fixed" not in report and "fix applied" not in report
    assert shot.read_text(encoding="utf-8") == SHOT


def test_diff_of_a_usdc_is_a_note_not_a_patch(tmp_path: Path, monkeypatch) -> None:
    source = Sdf.Layer.CreateAnonymous(".usda")
    source.ImportFromString(SHOT)
    crate = tmp_path / "shot.usdc"
    source.Export(str(crate))
    before = crate.read_bytes()
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(
        cli, ["check", "--isolated", "-j", "1", "--select", "SE006", "--diff", str(crate)]
    )
    assert crate.read_bytes() == before
    assert result.stdout == ""  # nothing a patch tool could apply
    assert "shot.usdc is a binary (crate) layer" in result.stderr
    assert "--fix would rewrite it with 1 fix(es) (SE006)" in result.stderr
    assert result.exit_code == 1  # still pending


def test_diff_refuses_what_fix_refuses(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    shot.chmod(0o444)
    result = CliRunner().invoke(
        cli, ["check", "--isolated", "-j", "1", "--select", "SE006", "--diff", str(shot)]
    )
    assert result.stdout == ""
    assert "read-only" in result.stderr
    assert result.exit_code == 0  # no fix pending


# -- --fix-to -------------------------------------------------------------------------


def _sublayered_on_top(tmp_path: Path, overrides: Path, shot: Path) -> Path:
    """The stage the fixes give: the --fix-to layer is its root, sublayering the shot."""
    layer = Sdf.Layer.OpenAsAnonymous(str(overrides))
    assert list(layer.subLayerPaths) == [shot.name]
    return overrides


def test_fix_to_writes_overrides_that_give_the_fixed_result(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT.replace("def Scope", "# kept\ndef Scope"))
    source = shot.read_bytes()
    overrides = tmp_path / "fixes.usda"
    result, document = check("--select", "SE006,SE007", "--fix-to", str(overrides), str(shot))
    assert result.exit_code == 0, result.output  # what remains with the overrides
    assert shot.read_bytes() == source  # sources untouched, comments and all
    assert codes(document) == []
    assert {fix["layer"] for fix in document["fixes"]} == {"fixes.usda"} or all(
        fix["layer"].endswith("fixes.usda") for fix in document["fixes"]
    )
    top = _sublayered_on_top(tmp_path, overrides, shot)
    # Fixed through the override layer: SE006 by a value, SE007's removed
    # instantaneousShutter by a block (SE007 wants no opinion at all, not even
    # the fallback false).
    _, on_top = check("--select", "SE006,SE007", str(top))
    assert codes(on_top) == []
    # The same composed result as fixing in place, as the rules read values (a
    # block reads as the fallback: usd-core's GetResolveInfo says Fallback,
    # although Python's Get() returns None for it).
    in_place = write(tmp_path / "in_place.usda", SHOT)
    check("--select", "SE006,SE007", "--fix", str(in_place))
    stages = Usd.Stage.Open(str(top)), Usd.Stage.Open(str(in_place))
    for name in ("aspectRatioConformPolicy", "instantaneousShutter", "disableMotionBlur"):
        top_value, in_place_value = (
            composed_value(stage.GetPrimAtPath("/Render/Settings"), name) for stage in stages
        )
        assert top_value == in_place_value, name
    # Idempotent: a second run finds nothing to override.
    written = overrides.read_bytes()
    _, again = check("--select", "SE006,SE007", "--fix-to", str(overrides), str(shot))
    assert again["fixes"] == [] and overrides.read_bytes() == written


def test_fix_to_overrides_removed_targets_with_an_explicit_list(tmp_path: Path) -> None:
    fixture = FIXTURES / "PR005_ordered_vars_invalid_target" / "fail_targets.usda"
    shot = write(tmp_path / "shot.usda", fixture.read_text(encoding="utf-8"))
    overrides = tmp_path / "fixes.usdc"
    result, document = check(
        "--select", "PR005", "--unsafe-fixes", "--fix-to", str(overrides), str(shot)
    )
    assert result.exit_code == 0, result.output
    assert overrides.read_bytes().startswith(b"PXR-USDC")
    top = _sublayered_on_top(tmp_path, overrides, shot)
    _, on_top = check("--select", "PR005", str(top))
    assert codes(on_top) == []
    golden = fixture.with_name("fail_targets.fixed.usda")
    fixed_stage, top_stage = Usd.Stage.Open(str(golden)), Usd.Stage.Open(str(top))
    for prim in fixed_stage.Traverse():
        rel = prim.GetRelationship("orderedVars")
        if rel:
            path = rel.GetPath()
            assert top_stage.GetRelationshipAtPath(path).GetTargets() == rel.GetTargets(), path


def test_unsafe_fixes_leave_no_product_without_render_vars(tmp_path: Path) -> None:
    # PR005's fix removed a product's only target: PR004, a product with no
    # RenderVars, was left where there was none before.
    fixture = FIXTURES / "PR005_ordered_vars_invalid_target" / "fail_no_usable_target.usda"
    shot = write(tmp_path / "shot.usda", fixture.read_text(encoding="utf-8"))
    _, before = check(str(shot))
    result, document = check("--fix", "--unsafe-fixes", str(shot))
    assert "PR004" not in codes(document), result.output
    assert sorted(codes(document)) == sorted(codes(before))
    assert shot.read_text(encoding="utf-8") == fixture.read_text(encoding="utf-8")


def test_fix_to_carries_stage_metadata(tmp_path: Path) -> None:
    # renderSettingsPrimPath counts only in the root layer: the --fix-to layer is the new root.
    fixture = FIXTURES / "ST003_render_settings_path_missing" / "fail_unset.usda"
    shot = write(tmp_path / "shot.usda", fixture.read_text(encoding="utf-8"))
    overrides = tmp_path / "fixes.usda"
    result, document = check("--select", "ST003", "--fix-to", str(overrides), str(shot))
    assert result.exit_code == 0  # ST003 is info
    assert codes(document) == []
    assert [fix["applied"] for fix in document["fixes"]] == [True]
    stage = Usd.Stage.Open(str(overrides))
    assert stage.GetMetadata("renderSettingsPrimPath") == "/Render/Settings"
    fixed = write(tmp_path / "fixed.usda", shot.read_text(encoding="utf-8"))
    check("--select", "ST003", "--fix", str(fixed))
    assert Usd.Stage.Open(str(fixed)).GetMetadata("renderSettingsPrimPath") == "/Render/Settings"


def test_fix_to_keeps_what_the_layer_already_has(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    overrides = write(
        tmp_path / "fixes.usda",
        '#usda 1.0\n\nover "World"\n{\n    custom int note = 7\n}\n',
    )
    check("--select", "SE006", "--fix-to", str(overrides), str(shot))
    layer = Sdf.Layer.OpenAsAnonymous(str(overrides))
    assert layer.GetAttributeAtPath("/World.note").default == 7
    assert layer.GetAttributeAtPath(POLICY).default == "cropAperture"


def test_fix_to_moves_a_prim_by_deactivating_the_old_one(tmp_path: Path) -> None:
    fixture = FIXTURES / "ST008_render_prim_outside_render_scope" / "fail_outside.usda"
    shot = write(tmp_path / "shot.usda", fixture.read_text(encoding="utf-8"))
    overrides = tmp_path / "fixes.usda"
    args = ("--select", "ST008", "--unsafe-fixes", "--fix-to", str(overrides), str(shot))
    _, document = check(*args)
    assert document["fixes"] and all(fix["applied"] for fix in document["fixes"])
    assert codes(document) == []
    fixed = write(tmp_path / "fixed.usda", shot.read_text(encoding="utf-8"))
    check("--select", "ST008", "--unsafe-fixes", "--fix", str(fixed))
    stages = [Usd.Stage.Open(str(layer)) for layer in (overrides, fixed)]
    paths = [[str(p.GetPath()) for p in stage.Traverse()] for stage in stages]
    assert paths[0] == paths[1]


def test_fix_to_a_value_then_a_move_of_its_prim(tmp_path: Path) -> None:
    # SE006 overrides a value on </Other/Settings>; ST008 then moves that prim.
    shot = write(tmp_path / "shot.usda", SHOT.replace('def Scope "Render"', 'def Scope "Other"'))
    overrides = tmp_path / "fixes.usda"
    args = ("--select", "SE006,ST008", "--unsafe-fixes", "--fix-to", str(overrides), str(shot))
    result, document = check(*args)
    assert result.exit_code == 0, result.output
    outcome = {fix["code"]: fix["applied"] for fix in document["fixes"]}
    assert outcome == {"SE006": True, "ST008": True}
    stage = Usd.Stage.Open(str(overrides))
    assert stage.GetAttributeAtPath(POLICY).Get() == "cropAperture"
    assert not stage.GetPrimAtPath("/Other/Settings").IsActive()


def test_an_unexpected_error_costs_one_fix_only(tmp_path: Path, monkeypatch) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)

    def broken(*args):
        raise RuntimeError("unexpected")

    monkeypatch.setattr(fixer.sources.Sources, "commit", broken)
    result, document = check("--select", "SE006", "--fix", str(shot))
    assert result.exit_code == 1  # a report, not a crash
    assert shot.read_text(encoding="utf-8") == SHOT
    (reason,) = reasons(document)
    assert "internal error while fixing: RuntimeError: unexpected" in reason


def test_fix_to_fixes_a_bad_value_the_override_layer_holds(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT.replace('"cropaperture"', '"expandAperture"'))
    overrides = write(tmp_path / "fixes.usda", SHOT.replace("def ", "over "))
    result, document = check("--select", "SE006", "--fix-to", str(overrides), str(shot))
    assert result.exit_code == 0, result.output
    assert [fix["applied"] for fix in document["fixes"]] == [True]
    layer = Sdf.Layer.OpenAsAnonymous(str(overrides))
    assert layer.GetAttributeAtPath(POLICY).default == "cropAperture"


# -- usage ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--unsafe-fixes"], "--unsafe-fixes needs --fix"),
        (["--diff", "--fix-to", "x.usda"], "either --diff or --fix-to"),
    ],
)
def test_flag_misuse_is_a_tool_error(tmp_path: Path, args: list[str], message: str) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    result, _ = check(*args, str(shot))
    assert result.exit_code == 2
    assert message in result.stderr


def test_fix_to_a_layer_with_comments_keeps_them(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    overrides = write(tmp_path / "fixes.usda", "#usda 1.0\n# reviewed by lighting\n")
    result, _ = check("--select", "SE006", "--fix-to", str(overrides), str(shot))
    assert result.exit_code == 0, result.output
    assert value(_sublayered_on_top(tmp_path, overrides, shot)) == "cropAperture"
    assert overrides.read_text(encoding="utf-8").startswith("#usda 1.0\n(\n")
    assert "# reviewed by lighting\n" in overrides.read_text(encoding="utf-8")


@pytest.mark.parametrize("link", ["symbolic", "hard"])
@pytest.mark.parametrize("linked", ["shot.usda", "base.usda"])
def test_fix_to_a_link_to_a_layer_of_the_stage_is_refused(
    tmp_path: Path, link: str, linked: str
) -> None:
    """Sdf tells layers apart by name: --fix-to through a link to the stage's
    root (or a sublayer) wrote the overrides into that source, sublayering itself."""
    write(tmp_path / "base.usda", "#usda 1.0\n")
    shot = write(tmp_path / "shot.usda", SHOT.replace("#usda 1.0", _SUBLAYERS_BASE))
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    overrides = tmp_path / "fixes.usda"
    if link == "symbolic":
        overrides.symlink_to(linked)
    else:
        os.link(tmp_path / linked, overrides)
    result, _ = check("--select", "SE006", "--fix-to", str(overrides), str(shot))
    assert result.exit_code == 2, result.output
    refusal = "the layer is part of the stage it fixes" if link == "symbolic" else "hard links"
    assert refusal in result.stderr
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir() if p != overrides} == before


def test_fix_to_a_layer_with_hard_links_is_refused(tmp_path: Path) -> None:
    """Replacing it would split the links, as --fix says of a source."""
    shot = write(tmp_path / "shot.usda", SHOT)
    overrides = write(tmp_path / "fixes.usda", "#usda 1.0\n")
    os.link(overrides, tmp_path / "other-name.usda")
    result, _ = check("--select", "SE006", "--fix-to", str(overrides), str(shot))
    assert result.exit_code == 2, result.output
    assert "fixes.usda: has 2 hard links" in result.stderr
    assert os.stat(overrides).st_ino == os.stat(tmp_path / "other-name.usda").st_ino
    assert overrides.read_text() == "#usda 1.0\n"


_SUBLAYERS_BASE = "#usda 1.0\n(\n    subLayers = [@./base.usda@]\n)"


def test_fix_to_takes_one_stage(tmp_path: Path) -> None:
    one, two = write(tmp_path / "a.usda", SHOT), write(tmp_path / "b.usda", SHOT)
    result, _ = check("--fix-to", str(tmp_path / "fixes.usda"), str(one), str(two))
    assert result.exit_code == 2
    assert "one stage" in result.stderr


def test_fix_to_an_unusable_layer_is_a_tool_error(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    result, _ = check("--fix-to", str(tmp_path / "no" / "fixes.usda"), str(shot))
    assert result.exit_code == 2
    assert "does not exist" in result.stderr
    assert os.listdir(tmp_path) == ["shot.usda"]


# -- the fixer's own guarantees, with rules made for the test ---------------------------


class _SettingsRule(Rule):
    """A rule for the test: fires on every RenderSettings with a given fix."""

    code = "TF001"
    name = "test-fix"
    severity = Severity.ERROR
    prim_types = (UsdRender.Settings,)
    fix_safety = "safe"
    apply = None

    def check_prim(self, prim, ctx):
        if not prim.GetCustomDataByKey("fixed"):
            yield Diagnostic(
                message="not fixed yet",
                at=prim,
                fix=Fix(description="mark", safe=True, apply=type(self).apply),
            )


def _fix_with(apply, path: Path, **options) -> fixer.FixRun:
    rule = type(
        "Rule", (_SettingsRule,), {"__doc__": _SettingsRule.__doc__, "apply": staticmethod(apply)}
    )
    return fixer.fix_files(Linter([rule()]), [str(path)], fixer.FixOptions(**options))


def _mark(stage: Usd.Stage) -> None:
    stage.GetPrimAtPath("/Render/Settings").SetCustomDataByKey("fixed", True)


def test_a_fix_that_raises_is_reported_and_undone(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)

    def half_then_raise(stage: Usd.Stage) -> None:
        _mark(stage)
        raise RuntimeError("boom")

    run = _fix_with(half_then_raise, shot)
    (outcome,) = run.outcomes
    assert not outcome.applied and "RuntimeError: boom" in outcome.reason
    assert shot.read_text(encoding="utf-8") == SHOT


def test_a_fix_that_changes_nothing_is_not_counted(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    run = _fix_with(lambda stage: None, shot)
    (outcome,) = run.outcomes
    assert outcome.reason == "the fix changed nothing"


def test_a_fix_that_also_edits_a_read_only_layer_is_undone(tmp_path: Path) -> None:
    weak = write(tmp_path / "weak.usda", '#usda 1.0\n\nover "Render"\n{\n}\n')
    shot = write(
        tmp_path / "shot.usda",
        SHOT.replace("#usda 1.0", "#usda 1.0\n(\n    subLayers = [@weak.usda@]\n)"),
    )
    before = shot.read_bytes()
    weak.chmod(0o444)

    def edit_both(stage: Usd.Stage) -> None:
        _mark(stage)
        weak_layer = stage.GetLayerStack()[-1]
        weak_layer.GetPrimAtPath("/Render").SetInfo("comment", "touched")

    try:
        run = _fix_with(edit_both, shot)
    finally:
        weak.chmod(0o644)
    (outcome,) = run.outcomes
    assert "also edits" in outcome.reason and "read-only" in outcome.reason
    assert shot.read_bytes() == before and "touched" not in weak.read_text(encoding="utf-8")


def test_a_fix_that_also_edits_a_referenced_layer_is_undone(tmp_path: Path) -> None:
    asset = write(tmp_path / "asset.usda", '#usda 1.0\n\ndef Scope "A"\n{\n}\n')
    text = SHOT.replace(
        'def Scope "Render"', 'def Scope "Render" (\n    references = @asset.usda@</A>\n)'
    )
    shot = write(tmp_path / "shot.usda", text)

    def edit_both(stage: Usd.Stage) -> None:
        _mark(stage)
        Sdf.Layer.Find(str(asset)).GetPrimAtPath("/A").SetInfo("comment", "touched")

    (outcome,) = _fix_with(edit_both, shot).outcomes
    assert "outside the stage's layer stack" in outcome.reason
    assert shot.read_text(encoding="utf-8") == text
    assert "touched" not in asset.read_text(encoding="utf-8")


def test_a_broken_file_is_reported_not_fixed(tmp_path: Path) -> None:
    broken = write(tmp_path / "broken.usda", '#usda 1.0\ndef Scope "A" {\n')
    result, document = check("--fix", str(broken))
    assert result.exit_code == 1
    assert codes(document) == ["ST001"] and document["fixes"] == []
    assert broken.read_text(encoding="utf-8") == '#usda 1.0\ndef Scope "A" {\n'


def test_fix_to_on_a_broken_file_reports_it(tmp_path: Path) -> None:
    broken = write(tmp_path / "broken.usda", '#usda 1.0\ndef Scope "A" {\n')
    result, document = check("--fix-to", str(tmp_path / "fixes.usda"), str(broken))
    assert result.exit_code == 1
    assert codes(document) == ["ST001"]
    assert not (tmp_path / "fixes.usda").exists()


def test_json_has_no_fixes_field_without_fixing(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    _, document = check("--select", "SE006", str(shot))
    assert "fixes" not in document
    assert document["files"][0]["findings"][0]["fix"] == {
        "description": 'set to "cropAperture"',
        "safe": True,
    }


def test_fix_handles_several_files_in_one_run(tmp_path: Path) -> None:
    one, two = write(tmp_path / "a.usda", SHOT), write(tmp_path / "b.usda", SHOT)
    result, document = check("--select", "SE006", "--fix", str(one), str(two))
    assert result.exit_code == 0, result.output
    assert value(one) == value(two) == "cropAperture"
    assert len(document["fixes"]) == 2


def _append_rule(code: str, token: str) -> type[Rule]:
    """A rule whose fix writes the list it read, plus ``token``."""

    def check_prim(self, prim, ctx):
        attr = prim.GetAttribute("includedPurposes")
        current = list(attr.Get() or [])
        if token not in current:

            def apply(stage: Usd.Stage) -> None:
                stage.GetAttributeAtPath(attr.GetPath()).Set([*current, token])

            yield Diagnostic(
                message=f"no {token}",
                at=attr,
                fix=Fix(description=f"add {token}", safe=True, apply=apply),
            )

    return type(
        f"Append{token}",
        (Rule,),
        {
            "__doc__": f"Appends {token}.",
            "code": code,
            "name": f"append-{token}",
            "severity": Severity.ERROR,
            "prim_types": (UsdRender.Settings,),
            "fix_safety": "safe",
            "check_prim": check_prim,
        },
    )


def test_fixes_on_one_property_run_in_rounds_and_keep_each_other(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    rules = [_append_rule("TF002", "alpha")(), _append_rule("TF003", "beta")()]
    run = fixer.fix_files(Linter(rules), [str(shot)], fixer.FixOptions())
    assert [o.applied for o in run.outcomes] == [True, True]
    attr = "/Render/Settings.includedPurposes"
    assert list(value(shot, attr)) == ["default", "render", "alpha", "beta"]


class _ChainRule(Rule):
    """A rule for the test: every RenderSettings wants a RenderSettings child,
    so each fix reveals another finding and fixing never converges."""

    code = "TF004"
    name = "test-chain"
    severity = Severity.ERROR
    prim_types = (UsdRender.Settings,)
    fix_safety = "safe"

    def check_prim(self, prim, ctx):
        if not prim.GetChildren():
            child = prim.GetPath().AppendChild("Next")

            def apply(stage: Usd.Stage) -> None:
                UsdRender.Settings.Define(stage, child)

            yield Diagnostic(
                message="no child", at=prim, fix=Fix(description="add", safe=True, apply=apply)
            )


def test_fixes_that_never_converge_stop_at_the_limit_with_a_note(
    tmp_path: Path, monkeypatch
) -> None:
    # Stopping was silent: the report showed one more fixable finding and no reason.
    monkeypatch.setattr(session, "MIN_ATTEMPTS", 5)
    monkeypatch.setattr(session, "MAX_ATTEMPTS_PER_FIX", 1)
    shot = write(tmp_path / "shot.usda", SHOT)
    run = fixer.fix_files(Linter([_ChainRule()]), [str(shot)], fixer.FixOptions())
    assert len(run.applied) == 5
    (note,) = run.notes
    assert "fixing stopped after 5 fix attempts" in note and "TF004" in note


def test_many_fixes_in_one_layer(tmp_path: Path) -> None:
    # Undo is by notice and replay, not a copy per fix: this stays well under a second.
    body = "".join(
        f'    def RenderSettings "S{i}"\n    {{\n'
        '        uniform token aspectRatioConformPolicy = "cropaperture"\n    }\n'
        for i in range(300)
    )
    text = f'#usda 1.0\n\ndef Scope "Render"\n{{\n{body}}}\n'
    shot, other = write(tmp_path / "shot.usda", text), write(tmp_path / "other.usda", text)
    _, document = check("--select", "SE006", "--fix", str(shot))
    assert sum(fix["applied"] for fix in document["fixes"]) == 300 and codes(document) == []
    _, document = check("--select", "SE006", "--fix-to", str(tmp_path / "o.usda"), str(other))
    assert sum(fix["applied"] for fix in document["fixes"]) == 300 and codes(document) == []
    assert other.read_text(encoding="utf-8") == text


def test_unfixable_rules_are_not_fixed(tmp_path: Path) -> None:
    # The catalog (CA006): teams that want the decision forced disable the fixer.
    shot = write(tmp_path / "shot.usda", SHOT)
    config = write(tmp_path / "lint.toml", 'unfixable = ["aspect-ratio-conform-policy-invalid"]\n')
    args = ["check", "-j", "1", "--config", str(config), "--format", "json"]
    result = CliRunner().invoke(cli, [*args, "--select", "SE006,SE007", "--fix", str(shot)])
    document = json.loads(result.stdout)
    assert {fix["code"] for fix in document["fixes"]} == {"SE007"}
    assert value(shot) == "cropaperture"
    assert codes(document) == ["SE006"]


def test_unfixable_names_a_rule(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    config = write(tmp_path / "lint.toml", 'unfixable = ["no-such-rule"]\n')
    result = CliRunner().invoke(cli, ["check", "--config", str(config), "--fix", str(shot)])
    assert result.exit_code == 2
    assert "unfixable" in result.stderr and "no-such-rule" in result.stderr


def test_a_stage_lint_pairs_each_finding_with_its_fix(tmp_path: Path) -> None:
    shot = write(tmp_path / "shot.usda", SHOT)
    stage = Usd.Stage.Open(str(shot))
    linter = Linter([rule() for rule in build_registry().rules])
    run = linter.run_stage(stage)
    pairs = [(finding, run.fix(finding)) for finding in run.findings]
    assert [finding for finding, _ in pairs] == linter.lint_stage(stage)
    assert pairs and any(fix for _, fix in pairs)
    for finding, fix in pairs:
        assert (fix is None) == (finding.fix is None)
        if fix is not None:
            assert (fix.description, fix.safe) == (finding.fix.description, finding.fix.safe)
