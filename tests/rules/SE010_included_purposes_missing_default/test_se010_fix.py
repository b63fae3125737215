"""SE010's fix: "default" is prepended in the layer that authors the list."""

from __future__ import annotations

from rule_support import (
    apply_fix,
    diagnostics,
    only,
    stage_from_text,
)

from usdrender_lint.rules.settings.se010_included_purposes_missing_default import (
    IncludedPurposesMissingDefault,
)


def test_se010_prepends_default_in_the_layer_that_authors_the_list() -> None:
    rule = IncludedPurposesMissingDefault()
    weaker = '#usda 1.0\nover "S"\n{\n    uniform token[] includedPurposes = ["render"]\n}\n'
    stage = stage_from_text('#usda 1.0\ndef RenderSettings "S"\n{\n}\n', weaker)
    layer = apply_fix(stage, only(rule, stage))
    assert layer != stage.GetRootLayer()
    edited = layer.GetAttributeAtPath("/S.includedPurposes").default
    assert list(edited) == ["default", "render"]
    assert not stage.GetRootLayer().GetAttributeAtPath("/S.includedPurposes")
    assert diagnostics(rule, stage) == []
