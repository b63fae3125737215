"""CA004's fix: a camera rig's Xform is retargeted to the Camera inside it."""

from __future__ import annotations

from pxr import Sdf, UsdRender
from rule_support import apply_fix, diagnostics, only, stage_from_text

from usdrender_lint.rules.camera.ca004_camera_target_not_camera import CameraTargetNotCamera


def test_ca004_fix_retargets_the_rig_camera() -> None:
    stage = stage_from_text(
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
    apply_fix(stage, only(CameraTargetNotCamera(), stage))
    rel = UsdRender.Settings(stage.GetPrimAtPath("/Settings")).GetCameraRel()
    assert list(rel.GetTargets()) == [Sdf.Path("/rig/cam")]
    assert not diagnostics(CameraTargetNotCamera(), stage)
