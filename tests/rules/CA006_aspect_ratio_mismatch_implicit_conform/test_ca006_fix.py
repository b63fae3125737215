"""CA006's fix: the implicit fallback policy is authored explicitly."""

from __future__ import annotations

from rule_support import apply_fix, diagnostics, only, stage_from_text

from usdrender_lint.rules.camera.ca006_aspect_ratio_mismatch_implicit_conform import (
    AspectRatioMismatchImplicitConform,
)


def test_ca006_fix_makes_the_implicit_policy_explicit() -> None:
    stage = stage_from_text(
        """#usda 1.0
def Camera "cam"
{
}
def RenderSettings "Settings"
{
    rel camera = </cam>
    uniform int2 resolution = (1920, 1080)
}
"""
    )
    diagnostic = only(AspectRatioMismatchImplicitConform(), stage)
    assert diagnostic.fix.safe
    apply_fix(stage, diagnostic)
    policy = stage.GetPrimAtPath("/Settings").GetAttribute("aspectRatioConformPolicy")
    assert policy.HasAuthoredValue() and policy.Get() == "expandAperture"
    assert not diagnostics(AspectRatioMismatchImplicitConform(), stage)
