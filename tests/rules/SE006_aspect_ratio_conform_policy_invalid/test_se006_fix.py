"""SE006's fix: a case slip in the policy token is corrected; an unknown word has no fix."""

from __future__ import annotations

from rule_support import (
    apply_fix,
    attribute_value,
    diagnostics,
    only,
    settings_layer,
    stage_from_text,
)

from usdrender_lint.rules.settings.se006_aspect_ratio_conform_policy_invalid import (
    AspectRatioConformPolicyInvalid,
)


def test_se006_fixes_a_case_slip() -> None:
    rule = AspectRatioConformPolicyInvalid()
    stage = stage_from_text(
        settings_layer('uniform token aspectRatioConformPolicy = "CROPAPERTURE"')
    )
    diagnostic = only(rule, stage)
    assert diagnostic.fix.safe
    apply_fix(stage, diagnostic)
    assert attribute_value(stage, "aspectRatioConformPolicy") == "cropAperture"
    assert diagnostics(rule, stage) == []


def test_se006_offers_no_fix_for_an_unknown_word() -> None:
    stage = stage_from_text(settings_layer('uniform token aspectRatioConformPolicy = "fit"'))
    assert only(AspectRatioConformPolicyInvalid(), stage).fix is None
