"""ST003's fix: the root layer's metadata names the stage's only RenderSettings."""

from __future__ import annotations

from pxr import UsdRender
from rule_support import ONE_SETTINGS, apply_fix, diagnostics, only, stage_from_text

from usdrender_lint.rules.stage.st003_render_settings_path_missing import RenderSettingsPathMissing


def test_st003_fix_authors_the_root_layer_metadata() -> None:
    stage = stage_from_text(ONE_SETTINGS)
    layer = apply_fix(stage, only(RenderSettingsPathMissing(), stage))
    assert layer == stage.GetRootLayer()
    assert stage.GetRootLayer().pseudoRoot.GetInfo("renderSettingsPrimPath") == "/Render/Settings"
    assert UsdRender.Settings.GetStageRenderSettings(stage)
    assert not diagnostics(RenderSettingsPathMissing(), stage)
