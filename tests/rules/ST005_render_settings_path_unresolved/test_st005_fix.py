"""ST005's fix: an unresolved renderSettingsPrimPath is rewritten to the only
RenderSettings; none is offered where the value lives in the session layer."""

from __future__ import annotations

from rule_support import ONE_SETTINGS, apply_fix, diagnostics, only, stage_from_text

from usdrender_lint.rules.stage.st005_render_settings_path_unresolved import (
    RenderSettingsPathUnresolved,
)
from usdrender_lint.rules.stage.st006_render_settings_path_not_render_settings import (
    RenderSettingsPathNotRenderSettings,
)


def test_st005_in_the_session_layer_has_no_fix() -> None:
    session = '#usda 1.0\n(\n    renderSettingsPrimPath = "/Render/Typo"\n)\n'
    stage = stage_from_text(ONE_SETTINGS, session=session)
    diagnostic = only(RenderSettingsPathUnresolved(), stage)
    assert diagnostic.layer == stage.GetSessionLayer()
    assert diagnostic.fix is None


def test_st005_fix_rewrites_to_the_only_settings() -> None:
    text = ONE_SETTINGS.replace(
        "#usda 1.0\n", '#usda 1.0\n(\n    renderSettingsPrimPath = "Render/Settings"\n)\n'
    )
    stage = stage_from_text(text)
    apply_fix(stage, only(RenderSettingsPathUnresolved(), stage))
    assert stage.GetMetadata("renderSettingsPrimPath") == "/Render/Settings"
    assert not diagnostics(RenderSettingsPathUnresolved(), stage)
    assert not diagnostics(RenderSettingsPathNotRenderSettings(), stage)
