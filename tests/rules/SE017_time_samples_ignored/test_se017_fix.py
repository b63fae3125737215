"""SE017's fix: constant time samples of a uniform attribute become a default;
no fix for varying or conflicting values, beyond the cap, or without a default."""

from __future__ import annotations

import pytest
from pxr import Gf, UsdRender
from rule_support import (
    apply_fix,
    diagnostics,
    only,
    settings_layer,
    stage_from_text,
)

from usdrender_lint.rules.settings.se017_time_samples_ignored import TimeSamplesIgnored


def test_se017_replaces_constant_samples_with_a_default() -> None:
    rule = TimeSamplesIgnored()
    stage = stage_from_text(
        settings_layer("uniform int2 resolution.timeSamples = {1: (640, 480), 2: (640, 480)}")
    )
    apply_fix(stage, only(rule, stage))
    attr = stage.GetPrimAtPath("/S").GetAttribute("resolution")
    assert attr.GetNumTimeSamples() == 0
    assert attr.Get() == Gf.Vec2i(640, 480)
    assert diagnostics(rule, stage) == []


@pytest.mark.parametrize(
    "authored",
    [
        "uniform int2 resolution.timeSamples = {1: (640, 480), 2: (1280, 960)}",
        "uniform int2 resolution = (1, 1)\n    uniform int2 resolution.timeSamples = {1: (2, 2)}",
    ],
)
def test_se017_offers_no_fix_for_varying_or_conflicting_values(authored: str) -> None:
    stage = stage_from_text(settings_layer(authored))
    assert only(TimeSamplesIgnored(), stage).fix is None


def test_se017_offers_no_fix_beyond_the_time_sample_cap() -> None:
    # Samples past the cap are not read, so they cannot be known to be equal.
    stage = stage_from_text(
        settings_layer("uniform int2 resolution.timeSamples = {1: (8, 8), 2: (8, 8)}")
    )
    assert only(TimeSamplesIgnored(), stage, cap=1).fix is None
    assert only(TimeSamplesIgnored(), stage, cap=0).fix is None


def test_se017_product_name_without_default_has_no_fix() -> None:
    stage = stage_from_text(
        '#usda 1.0\ndef RenderProduct "P"\n{\n    token productName.timeSamples = {1: "a.exr"}\n}\n'
    )
    diagnostic = only(TimeSamplesIgnored(), stage)
    assert diagnostic.fix is None and "no default" in diagnostic.message


def test_render_prim_types_cover_every_render_schema() -> None:
    stage = stage_from_text(
        '#usda 1.0\ndef RenderPass "Pass"\n'
        '{\n    uniform token passType.timeSamples = {1: "x"}\n}\n'
    )
    assert stage.GetPrimAtPath("/Pass").IsA(UsdRender.Pass)
    assert only(TimeSamplesIgnored(), stage).fix is not None
