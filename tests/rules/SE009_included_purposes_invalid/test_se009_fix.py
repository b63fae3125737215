"""SE009's fix: repeated purposes are dropped in order; an unknown token has no fix."""

from __future__ import annotations

from rule_support import (
    apply_fix,
    attribute_value,
    diagnostics,
    only,
    settings_layer,
    stage_from_text,
)

from usdrender_lint.rules.settings.se009_included_purposes_invalid import IncludedPurposesInvalid


def test_se009_drops_repeats_keeping_order() -> None:
    rule = IncludedPurposesInvalid()
    stage = stage_from_text(
        settings_layer('uniform token[] includedPurposes = ["render", "default", "render"]')
    )
    apply_fix(stage, only(rule, stage))
    assert list(attribute_value(stage, "includedPurposes")) == ["render", "default"]
    assert diagnostics(rule, stage) == []


def test_se009_offers_no_fix_when_a_token_is_unknown() -> None:
    stage = stage_from_text(
        settings_layer('uniform token[] includedPurposes = ["default", "preview", "preview"]')
    )
    assert only(IncludedPurposesInvalid(), stage).fix is None
