"""ST007's fix: the strongest sublayer value is copied into the root layer."""

from __future__ import annotations

from rule_support import ONE_SETTINGS, apply_fix, diagnostics, stage_from_text

from usdrender_lint.rules.stage.st007_render_settings_path_in_sublayer import (
    RenderSettingsPathInSublayer,
)


def test_st007_fix_copies_the_strongest_sublayer_value_into_the_root() -> None:
    weaker = '#usda 1.0\n(\n    renderSettingsPrimPath = "/Render/Other"\n)\n'
    stronger = '#usda 1.0\n(\n    renderSettingsPrimPath = "/Render/Settings"\n)\n'
    stage = stage_from_text(ONE_SETTINGS, stronger, weaker)
    found = diagnostics(RenderSettingsPathInSublayer(), stage)
    assert len(found) == 2
    (fixable,) = [d for d in found if d.fix is not None]
    assert fixable.layer.pseudoRoot.GetInfo("renderSettingsPrimPath") == "/Render/Settings"
    assert apply_fix(stage, fixable) == stage.GetRootLayer()
    assert stage.GetMetadata("renderSettingsPrimPath") == "/Render/Settings"
    # The redundant copy is silent; the weaker, different value is still reported.
    (remaining,) = diagnostics(RenderSettingsPathInSublayer(), stage)
    assert '"/Render/Other"' in remaining.message and remaining.fix is None
