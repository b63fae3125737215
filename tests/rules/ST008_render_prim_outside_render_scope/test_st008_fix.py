"""ST008's fix: the prim moves under </Render>, unless the destination is taken."""

from __future__ import annotations

from pathlib import Path

from pxr import Sdf, Usd, UsdRender
from rule_support import apply_fix, diagnostics, only, stage_from_text

from usdrender_lint.rules.stage.st008_render_prim_outside_render_scope import (
    RenderPrimOutsideRenderScope,
)


def test_st008_fix_moves_the_prim_under_render() -> None:
    stage = stage_from_text('#usda 1.0\ndef RenderSettings "Settings"\n{\n}\n')
    diagnostic = only(RenderPrimOutsideRenderScope(), stage)
    apply_fix(stage, diagnostic)
    assert stage.GetPrimAtPath("/Render/Settings").IsA(UsdRender.Settings)
    assert not stage.GetPrimAtPath("/Settings")
    assert not diagnostics(RenderPrimOutsideRenderScope(), stage)


def test_st008_no_fix_when_the_destination_is_taken() -> None:
    stage = stage_from_text(
        '#usda 1.0\ndef RenderSettings "Settings"\n{\n}\n'
        'def Scope "Render"\n{\n    def Scope "Settings"\n    {\n    }\n}\n'
    )
    assert only(RenderPrimOutsideRenderScope(), stage).fix is None


def test_st008_fix_carries_render_settings_prim_path_and_sublayer_targets(
    tmp_path: Path,
) -> None:
    """The move left renderSettingsPrimPath naming the old path (ST005's error
    after the fix); the namespace editor rewrites the targets of the layer stack,
    a sublayer's included."""
    (tmp_path / "passes.usda").write_text(
        '#usda 1.0\ndef Scope "Render"\n{\n    def RenderPass "pass"\n    {\n'
        "        rel renderSource = </Settings>\n    }\n}\n"
    )
    root = tmp_path / "shot.usda"
    root.write_text(
        '#usda 1.0\n(\n    renderSettingsPrimPath = "/Settings"\n'
        "    subLayers = [@./passes.usda@]\n)\n\n"
        'def RenderSettings "Settings"\n{\n    rel products = </Settings/beauty>\n\n'
        '    def RenderProduct "beauty"\n    {\n    }\n}\n'
    )
    stage = Usd.Stage.Open(str(root))
    # The product moves with its settings (its own finding offers no fix).
    (movable,) = [d for d in diagnostics(RenderPrimOutsideRenderScope(), stage) if d.fix]
    apply_fix(stage, movable)
    assert stage.GetMetadata("renderSettingsPrimPath") == "/Render/Settings"
    settings = stage.GetPrimAtPath("/Render/Settings")
    assert settings.GetRelationship("products").GetTargets() == [
        Sdf.Path("/Render/Settings/beauty")
    ]
    source = stage.GetPrimAtPath("/Render/pass").GetRelationship("renderSource")
    assert source.GetTargets() == [Sdf.Path("/Render/Settings")]
    assert not diagnostics(RenderPrimOutsideRenderScope(), stage)


def test_st008_fix_leaves_a_settings_path_naming_another_prim() -> None:
    stage = stage_from_text(
        '#usda 1.0\n(\n    renderSettingsPrimPath = "/Render/Main"\n)\n'
        'def RenderSettings "Settings"\n{\n}\n'
        'def Scope "Render"\n{\n    def RenderSettings "Main"\n    {\n    }\n}\n'
    )
    apply_fix(stage, only(RenderPrimOutsideRenderScope(), stage))
    assert stage.GetMetadata("renderSettingsPrimPath") == "/Render/Main"
    assert stage.GetPrimAtPath("/Render/Settings")
