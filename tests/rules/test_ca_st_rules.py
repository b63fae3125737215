"""CA and ST rules beyond the fixtures: each fix edits the layer the fixer
targets and silences its rule, fixes are withheld where the catalog's
condition fails, the session layer's metadata counts, and camera values are
evaluated over time samples up to the cap."""

from __future__ import annotations

from pathlib import Path

from pxr import Sdf, Usd, UsdGeom, UsdRender
from usdrender_lint.rules.camera.ca001_camera_unset import CameraUnset
from usdrender_lint.rules.camera.ca004_camera_target_not_camera import CameraTargetNotCamera
from usdrender_lint.rules.camera.ca005_camera_optics_invalid import CameraOpticsInvalid
from usdrender_lint.rules.camera.ca006_aspect_ratio_mismatch_implicit_conform import (
    AspectRatioMismatchImplicitConform,
)
from usdrender_lint.rules.stage.st003_render_settings_path_missing import RenderSettingsPathMissing
from usdrender_lint.rules.stage.st005_render_settings_path_unresolved import (
    RenderSettingsPathUnresolved,
)
from usdrender_lint.rules.stage.st006_render_settings_path_not_render_settings import (
    RenderSettingsPathNotRenderSettings,
)
from usdrender_lint.rules.stage.st007_render_settings_path_in_sublayer import (
    RenderSettingsPathInSublayer,
)
from usdrender_lint.rules.stage.st008_render_prim_outside_render_scope import (
    RenderPrimOutsideRenderScope,
)
from usdrender_lint.rules.stage.st010_unknown_render_prim_type import UnknownRenderPrimType

from usdrender_lint.api import Context, Diagnostic, Rule
from usdrender_lint.api.resolve import joint_evaluation_times
from usdrender_lint.engine import Linter

RENDER_SCHEMAS = (UsdRender.Settings, UsdRender.Product, UsdRender.Var, UsdRender.Pass)


def _layer(body: str) -> Sdf.Layer:
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(body)
    return layer


def _stage(body: str, *sublayers: str, session: str | None = None) -> Usd.Stage:
    """An in-memory stage from usda text (header included); ``sublayers`` are
    appended to the root layer's subLayers, ``session`` is the session layer."""
    root = _layer(body)
    # Anonymous layers live only while referenced: hold them until the stage does.
    weaker = [_layer(text) for text in sublayers]
    root.subLayerPaths = [layer.identifier for layer in weaker]
    if session is None:
        return Usd.Stage.Open(root)
    return Usd.Stage.Open(root, _layer(session))


def _context(stage: Usd.Stage) -> Context:
    """What the engine's walk gives the rules (render prims, unknown types)."""
    ctx = Context(stage=stage, file="memory.usda")
    for prim in stage.Traverse():
        for schema in RENDER_SCHEMAS:
            if prim.IsA(schema):
                ctx.render_prims.setdefault(schema, []).append(prim)
        if prim.GetTypeName() and prim.GetPrimTypeInfo().GetSchemaType().isUnknown:
            ctx.unknown_type_prims.append(prim)
    return ctx


def _diagnostics(rule: Rule, stage: Usd.Stage) -> list[Diagnostic]:
    ctx = _context(stage)
    found = list(rule.check_stage(ctx))
    for prim in stage.Traverse():
        if any(prim.IsA(schema) for schema in rule.prim_types):
            found.extend(rule.check_prim(prim, ctx))
    return found


def _only(rule: Rule, stage: Usd.Stage) -> Diagnostic:
    (diagnostic,) = _diagnostics(rule, stage)
    return diagnostic


def _target_layer(stage: Usd.Stage, diagnostic: Diagnostic) -> Sdf.Layer:
    """The fixer's choice: the fix's layer, else the finding's, else the
    strongest opinion on ``at``, else the root layer."""
    if diagnostic.fix.layer is not None:
        return diagnostic.fix.layer
    if diagnostic.layer is not None:
        return diagnostic.layer
    at = diagnostic.at
    if isinstance(at, Usd.Property):
        return at.GetPropertyStack(Usd.TimeCode.Default())[0].layer
    if isinstance(at, Usd.Prim):
        return at.GetPrimStack()[0].layer
    return stage.GetRootLayer()


def _apply(stage: Usd.Stage, diagnostic: Diagnostic) -> Sdf.Layer:
    layer = _target_layer(stage, diagnostic)
    stage.SetEditTarget(Usd.EditTarget(layer))
    diagnostic.fix.apply(stage)
    return layer


SETTINGS_WITHOUT_CAMERA = """#usda 1.0
def Xform "World"
{
    def Camera "cam"
    {
    }
}
def Scope "Render"
{
    def RenderSettings "Settings"
    {
    }
}
"""


# -- CA ------------------------------------------------------------------------------


def test_ca001_fix_targets_the_only_camera() -> None:
    stage = _stage(SETTINGS_WITHOUT_CAMERA)
    diagnostic = _only(CameraUnset(), stage)
    assert diagnostic.fix is not None and not diagnostic.fix.safe
    _apply(stage, diagnostic)
    rel = UsdRender.Settings(stage.GetPrimAtPath("/Render/Settings")).GetCameraRel()
    assert list(rel.GetTargets()) == [Sdf.Path("/World/cam")]
    assert not _diagnostics(CameraUnset(), stage)


def test_ca001_no_fix_with_two_cameras() -> None:
    stage = _stage(SETTINGS_WITHOUT_CAMERA)
    UsdGeom.Camera.Define(stage, "/World/witness")
    assert _only(CameraUnset(), stage).fix is None


def test_ca004_fix_retargets_the_rig_camera() -> None:
    stage = _stage(
        """#usda 1.0
def Xform "rig"
{
    def Camera "cam"
    {
    }
}
def RenderSettings "Settings"
{
    rel camera = </rig>
}
"""
    )
    _apply(stage, _only(CameraTargetNotCamera(), stage))
    rel = UsdRender.Settings(stage.GetPrimAtPath("/Settings")).GetCameraRel()
    assert list(rel.GetTargets()) == [Sdf.Path("/rig/cam")]
    assert not _diagnostics(CameraTargetNotCamera(), stage)


def test_ca006_fix_makes_the_implicit_policy_explicit() -> None:
    stage = _stage(
        """#usda 1.0
def Camera "cam"
{
}
def RenderSettings "Settings"
{
    rel camera = </cam>
    uniform int2 resolution = (1920, 1080)
}
"""
    )
    diagnostic = _only(AspectRatioMismatchImplicitConform(), stage)
    assert diagnostic.fix.safe
    _apply(stage, diagnostic)
    policy = stage.GetPrimAtPath("/Settings").GetAttribute("aspectRatioConformPolicy")
    assert policy.HasAuthoredValue() and policy.Get() == "expandAperture"
    assert not _diagnostics(AspectRatioMismatchImplicitConform(), stage)


def _lint_text(tmp_path: Path, text: str, cap: int) -> list[str]:
    path = tmp_path / "shot.usda"
    path.write_text(text, encoding="utf-8")
    linter = Linter([CameraOpticsInvalid()], time_sample_cap=cap, raise_errors=True)
    return [f.message for f in linter.lint_path(str(path)).findings]


def test_ca005_time_samples_beyond_the_cap_are_not_read(tmp_path: Path) -> None:
    text = """#usda 1.0
def Camera "cam"
{
    float focalLength.timeSamples = {
        1: 35,
        2: 40,
        3: 0,
    }
}
def RenderSettings "Settings"
{
    rel camera = </cam>
}
"""
    assert _lint_text(tmp_path, text, cap=2) == []
    (message,) = _lint_text(tmp_path, text, cap=3)
    assert "focalLength is 0" in message and "time 3" in message


def test_joint_evaluation_times_merge_sort_and_cap() -> None:
    stage = _stage(
        """#usda 1.0
def Camera "cam"
{
    double shutter:open.timeSamples = { 5: 0, 1: 0 }
    double shutter:close.timeSamples = { 3: 1, 5: 1, 9: 1 }
}
"""
    )
    camera = stage.GetPrimAtPath("/cam")
    attrs = [camera.GetAttribute("shutter:open"), camera.GetAttribute("shutter:close")]
    times = list(joint_evaluation_times(attrs, cap=3))
    assert times[0].IsDefault()
    assert [t.GetValue() for t in times[1:]] == [1.0, 3.0, 5.0]


# -- ST ------------------------------------------------------------------------------

ONE_SETTINGS = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
    }
}
"""


def test_st003_fix_authors_the_root_layer_metadata() -> None:
    stage = _stage(ONE_SETTINGS)
    layer = _apply(stage, _only(RenderSettingsPathMissing(), stage))
    assert layer == stage.GetRootLayer()
    assert stage.GetRootLayer().pseudoRoot.GetInfo("renderSettingsPrimPath") == "/Render/Settings"
    assert UsdRender.Settings.GetStageRenderSettings(stage)
    assert not _diagnostics(RenderSettingsPathMissing(), stage)


def test_session_layer_metadata_counts() -> None:
    session = '#usda 1.0\n(\n    renderSettingsPrimPath = "/Render/Settings"\n)\n'
    stage = _stage(ONE_SETTINGS, session=session)
    assert not _diagnostics(RenderSettingsPathMissing(), stage)
    assert not _diagnostics(RenderSettingsPathInSublayer(), stage)


def test_st005_in_the_session_layer_has_no_fix() -> None:
    session = '#usda 1.0\n(\n    renderSettingsPrimPath = "/Render/Typo"\n)\n'
    stage = _stage(ONE_SETTINGS, session=session)
    diagnostic = _only(RenderSettingsPathUnresolved(), stage)
    assert diagnostic.layer == stage.GetSessionLayer()
    assert diagnostic.fix is None


def test_st005_fix_rewrites_to_the_only_settings() -> None:
    text = ONE_SETTINGS.replace(
        "#usda 1.0\n", '#usda 1.0\n(\n    renderSettingsPrimPath = "Render/Settings"\n)\n'
    )
    stage = _stage(text)
    _apply(stage, _only(RenderSettingsPathUnresolved(), stage))
    assert stage.GetMetadata("renderSettingsPrimPath") == "/Render/Settings"
    assert not _diagnostics(RenderSettingsPathUnresolved(), stage)
    assert not _diagnostics(RenderSettingsPathNotRenderSettings(), stage)


def test_st007_fix_copies_the_strongest_sublayer_value_into_the_root() -> None:
    weaker = '#usda 1.0\n(\n    renderSettingsPrimPath = "/Render/Other"\n)\n'
    stronger = '#usda 1.0\n(\n    renderSettingsPrimPath = "/Render/Settings"\n)\n'
    stage = _stage(ONE_SETTINGS, stronger, weaker)
    diagnostics = _diagnostics(RenderSettingsPathInSublayer(), stage)
    assert len(diagnostics) == 2
    (fixable,) = [d for d in diagnostics if d.fix is not None]
    assert fixable.layer.pseudoRoot.GetInfo("renderSettingsPrimPath") == "/Render/Settings"
    assert _apply(stage, fixable) == stage.GetRootLayer()
    assert stage.GetMetadata("renderSettingsPrimPath") == "/Render/Settings"
    # The redundant copy is silent; the weaker, different value is still reported.
    (remaining,) = _diagnostics(RenderSettingsPathInSublayer(), stage)
    assert '"/Render/Other"' in remaining.message and remaining.fix is None


def test_st008_fix_moves_the_prim_under_render() -> None:
    stage = _stage('#usda 1.0\ndef RenderSettings "Settings"\n{\n}\n')
    diagnostic = _only(RenderPrimOutsideRenderScope(), stage)
    _apply(stage, diagnostic)
    assert stage.GetPrimAtPath("/Render/Settings").IsA(UsdRender.Settings)
    assert not stage.GetPrimAtPath("/Settings")
    assert not _diagnostics(RenderPrimOutsideRenderScope(), stage)


def test_st008_no_fix_when_the_destination_is_taken() -> None:
    stage = _stage(
        '#usda 1.0\ndef RenderSettings "Settings"\n{\n}\n'
        'def Scope "Render"\n{\n    def Scope "Settings"\n    {\n    }\n}\n'
    )
    assert _only(RenderPrimOutsideRenderScope(), stage).fix is None


def test_st010_fix_retypes_in_the_authoring_sublayer() -> None:
    typo = '#usda 1.0\ndef Scope "Render"\n{\n    def RenderProdcut "Beauty"\n    {\n    }\n}\n'
    stage = _stage('#usda 1.0\nover "Render"\n{\n    over "Beauty"\n    {\n    }\n}\n', typo)
    diagnostic = _only(UnknownRenderPrimType(), stage)
    layer = _apply(stage, diagnostic)
    assert layer != stage.GetRootLayer()
    assert layer.GetPrimAtPath("/Render/Beauty").typeName == "RenderProduct"
    assert stage.GetPrimAtPath("/Render/Beauty").IsA(UsdRender.Product)
    assert not _diagnostics(UnknownRenderPrimType(), stage)


def test_st010_no_fix_without_a_unique_close_type() -> None:
    stage = _stage(
        '#usda 1.0\ndef Scope "Render"\n{\n    def ArnoldOptions "Options"\n    {\n    }\n}\n'
    )
    diagnostic = _only(UnknownRenderPrimType(), stage)
    assert diagnostic.fix is None
    assert "did you mean" not in diagnostic.message
