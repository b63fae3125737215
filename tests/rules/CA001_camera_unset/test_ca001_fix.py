"""CA001's fix: the settings get the stage's only camera; with two there is no fix."""

from __future__ import annotations

from pxr import Sdf, UsdGeom, UsdRender
from rule_support import apply_fix, diagnostics, only, stage_from_text

from usdrender_lint.rules.camera.ca001_camera_unset import CameraUnset

#: A product of a settings without a camera (a settings alone is no CA001: R2-2).
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
        rel products = </Render/Beauty>
    }
    def RenderProduct "Beauty"
    {
        token productName = "beauty.exr"
    }
}
"""


def test_ca001_fix_targets_the_only_camera() -> None:
    stage = stage_from_text(SETTINGS_WITHOUT_CAMERA)
    diagnostic = only(CameraUnset(), stage)
    assert diagnostic.fix is not None and not diagnostic.fix.safe
    apply_fix(stage, diagnostic)
    rel = UsdRender.Settings(stage.GetPrimAtPath("/Render/Settings")).GetCameraRel()
    assert list(rel.GetTargets()) == [Sdf.Path("/World/cam")]
    assert not diagnostics(CameraUnset(), stage)


def test_ca001_no_fix_with_two_cameras() -> None:
    stage = stage_from_text(SETTINGS_WITHOUT_CAMERA)
    UsdGeom.Camera.Define(stage, "/World/witness")
    assert only(CameraUnset(), stage).fix is None
