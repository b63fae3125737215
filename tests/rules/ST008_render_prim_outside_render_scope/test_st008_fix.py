"""ST008's fix: the prim moves under </Render>, unless the destination is taken."""

from __future__ import annotations

from pxr import UsdRender
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
