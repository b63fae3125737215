"""SE011's fix: all-purpose aliases map to "", repeats are dropped; other
problems have no fix."""

from __future__ import annotations

import pytest
from rule_support import (
    apply_fix,
    attribute_value,
    diagnostics,
    only,
    settings_layer,
    stage_from_text,
)

from usdrender_lint.rules.settings.se011_material_binding_purposes_invalid import (
    MaterialBindingPurposesInvalid,
)


@pytest.mark.parametrize(
    ("authored", "fixed"),
    [
        ('["full", "allPurpose"]', ["full", ""]),
        ('["all", "preview", ""]', ["", "preview"]),
        ('["full", "full"]', ["full"]),
    ],
)
def test_se011_maps_all_purpose_aliases_and_drops_repeats(authored: str, fixed: list) -> None:
    rule = MaterialBindingPurposesInvalid()
    stage = stage_from_text(settings_layer(f"uniform token[] materialBindingPurposes = {authored}"))
    apply_fix(stage, only(rule, stage))
    assert list(attribute_value(stage, "materialBindingPurposes")) == fixed
    assert diagnostics(rule, stage) == []


@pytest.mark.parametrize("authored", ['["render"]', "[]", '["full", "Preview"]'])
def test_se011_offers_no_fix_for_other_problems(authored: str) -> None:
    stage = stage_from_text(settings_layer(f"uniform token[] materialBindingPurposes = {authored}"))
    assert only(MaterialBindingPurposesInvalid(), stage).fix is None
