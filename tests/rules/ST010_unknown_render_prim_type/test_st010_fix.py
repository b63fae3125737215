"""ST010's fix: a typo'd render type is retyped in the sublayer that authors it;
without a unique close type there is no fix and no suggestion."""

from __future__ import annotations

from pxr import UsdRender
from rule_support import apply_fix, diagnostics, only, stage_from_text

from usdrender_lint.rules.stage.st010_unknown_render_prim_type import UnknownRenderPrimType


def test_st010_fix_retypes_in_the_authoring_sublayer() -> None:
    typo = '#usda 1.0\ndef Scope "Render"\n{\n    def RenderProdcut "Beauty"\n    {\n    }\n}\n'
    stage = stage_from_text(
        '#usda 1.0\nover "Render"\n{\n    over "Beauty"\n    {\n    }\n}\n', typo
    )
    diagnostic = only(UnknownRenderPrimType(), stage)
    layer = apply_fix(stage, diagnostic)
    assert layer != stage.GetRootLayer()
    assert layer.GetPrimAtPath("/Render/Beauty").typeName == "RenderProduct"
    assert stage.GetPrimAtPath("/Render/Beauty").IsA(UsdRender.Product)
    assert not diagnostics(UnknownRenderPrimType(), stage)


def test_st010_no_fix_without_a_unique_close_type() -> None:
    stage = stage_from_text(
        '#usda 1.0\ndef Scope "Render"\n{\n    def ArnoldOptions "Options"\n    {\n    }\n}\n'
    )
    diagnostic = only(UnknownRenderPrimType(), stage)
    assert diagnostic.fix is None
    assert "did you mean" not in diagnostic.message
