"""The session layer's renderSettingsPrimPath counts for the ST rules (ST003, ST007)."""

from __future__ import annotations

from pathlib import Path

from rule_support import ONE_SETTINGS, diagnostics, stage_from_text

import usdrender_lint
from usdrender_lint.rules.stage.st003_render_settings_path_missing import RenderSettingsPathMissing
from usdrender_lint.rules.stage.st007_render_settings_path_in_sublayer import (
    RenderSettingsPathInSublayer,
)


def test_session_layer_metadata_counts() -> None:
    session = '#usda 1.0\n(\n    renderSettingsPrimPath = "/Render/Settings"\n)\n'
    stage = stage_from_text(ONE_SETTINGS, session=session)
    assert not diagnostics(RenderSettingsPathMissing(), stage)
    assert not diagnostics(RenderSettingsPathInSublayer(), stage)


def test_a_cycle_through_the_session_layer_stack_reads_the_same_every_time(
    tmp_path: Path,
) -> None:
    """USD names the stage's layer stack, session layer included, in a cycle
    error: its identifier's address must not make each lint's ST002 differ."""
    shot = tmp_path / "shot.usda"
    shot.write_text(
        '#usda 1.0\n(\n    defaultPrim = "Render"\n)\n'
        'def Scope "Render" (\n    references = @./shot.usda@\n)\n{\n}\n'
    )
    messages = [
        [f.message for f in usdrender_lint.lint_file(shot, select=["ST002"]).findings]
        for _ in range(2)
    ]
    assert messages[0] == messages[1]
    assert "Cycle detected" in messages[0][0]
    assert "anon:0x" not in messages[0][0]


def test_st002_names_the_user_s_layers_not_the_tool_s_session_layer(tmp_path: Path) -> None:
    """USD names a layer stack by its layers, the session layer the tool opens
    the stage with included; that one is named after the file linted, so a text
    linted under another name (an editor's buffer) read differently."""
    text = (
        '#usda 1.0\n(\n    defaultPrim = "Render"\n)\n'
        'def Scope "Render" (\n    references = @./shot.usda@\n)\n{\n}\n'
    )
    shot = tmp_path / "shot.usda"
    shot.write_text(text)
    (message,) = [f.message for f in usdrender_lint.lint_file(shot, select=["ST002"]).findings]
    assert "Cycle detected" in message
    assert "session.usda" not in message
