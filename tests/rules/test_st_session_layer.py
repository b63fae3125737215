"""The session layer's renderSettingsPrimPath counts for the ST rules (ST003, ST007)."""

from __future__ import annotations

from rule_support import ONE_SETTINGS, diagnostics, stage_from_text

from usdrender_lint.rules.stage.st003_render_settings_path_missing import RenderSettingsPathMissing
from usdrender_lint.rules.stage.st007_render_settings_path_in_sublayer import (
    RenderSettingsPathInSublayer,
)


def test_session_layer_metadata_counts() -> None:
    session = '#usda 1.0\n(\n    renderSettingsPrimPath = "/Render/Settings"\n)\n'
    stage = stage_from_text(ONE_SETTINGS, session=session)
    assert not diagnostics(RenderSettingsPathMissing(), stage)
    assert not diagnostics(RenderSettingsPathInSublayer(), stage)
