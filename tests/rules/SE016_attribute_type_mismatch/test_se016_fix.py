"""SE016's fix: the spec is re-authored with the schema's type (values and time
samples converted) in the layer that holds the mistake; none when the value would change."""

from __future__ import annotations

import pytest
from pxr import Gf, Sdf
from rule_support import (
    apply_fix,
    attribute_value,
    diagnostics,
    only,
    settings_layer,
    stage_from_text,
)

from usdrender_lint.rules.settings.se016_attribute_type_mismatch import AttributeTypeMismatch


@pytest.mark.parametrize(
    ("path", "authored", "name", "expected"),
    [
        ("/S", "uniform float2 resolution = (1920, 1080)", "resolution", Gf.Vec2i(1920, 1080)),
        (
            "/S",
            "uniform double4 dataWindowNDC = (0, 0, 0.5, 1)",
            "dataWindowNDC",
            Gf.Vec4f(0, 0, 0.5, 1),
        ),
        ("/S", "uniform int pixelAspectRatio = 2", "pixelAspectRatio", 2.0),
        ("/P", 'string productName = "beauty.exr"', "productName", "beauty.exr"),
        ("/Pass", 'uniform string fileName = "a.usd"', "fileName", Sdf.AssetPath("a.usd")),
    ],
)
def test_se016_re_authors_the_spec_with_the_schema_type(path, authored, name, expected) -> None:
    rule = AttributeTypeMismatch()
    kind = {"/S": "RenderSettings", "/P": "RenderProduct", "/Pass": "RenderPass"}[path]
    stage = stage_from_text(f'#usda 1.0\ndef {kind} "{path[1:]}"\n{{\n    {authored}\n}}\n')
    layer = apply_fix(stage, only(rule, stage))
    spec = layer.GetAttributeAtPath(f"{path}.{name}")
    definition = stage.GetPrimAtPath(path).GetPrimDefinition().GetAttributeDefinition(name)
    assert spec.typeName == definition.GetTypeName()
    assert attribute_value(stage, name, path) == expected
    assert diagnostics(rule, stage) == []


def test_se016_converts_time_samples_and_keeps_variability() -> None:
    rule = AttributeTypeMismatch()
    stage = stage_from_text(
        settings_layer("uniform float2 resolution.timeSamples = {1: (64, 32), 2: (128, 64)}")
    )
    layer = apply_fix(stage, only(rule, stage))
    spec = layer.GetAttributeAtPath("/S.resolution")
    assert spec.variability == Sdf.VariabilityUniform
    assert layer.QueryTimeSample(spec.path, 2) == Gf.Vec2i(128, 64)
    assert isinstance(layer.QueryTimeSample(spec.path, 1), Gf.Vec2i)


def test_se016_keeps_the_specs_other_fields() -> None:
    """The re-authored spec lost its connections, documentation and customData:
    a safe fix changes the type, nothing else."""
    rule = AttributeTypeMismatch()
    stage = stage_from_text(
        settings_layer(
            'custom uniform float2 resolution = (1920, 1080) (\n        doc = "plate"\n'
            '        customData = {\n            string source = "edit"\n        }\n    )\n'
            "    uniform float2 resolution.connect = </S.plate>"
        )
    )
    before = stage.GetRootLayer().GetAttributeAtPath("/S.resolution")
    fields = {
        k: before.GetInfo(k) for k in before.ListInfoKeys() if k not in ("typeName", "default")
    }
    layer = apply_fix(stage, only(rule, stage))
    spec = layer.GetAttributeAtPath("/S.resolution")
    assert spec.typeName == Sdf.ValueTypeNames.Int2
    assert {k: spec.GetInfo(k) for k in spec.ListInfoKeys() if k in fields} == fields
    assert set(fields) <= set(spec.ListInfoKeys())
    assert list(spec.connectionPathList.explicitItems) == [Sdf.Path("/S.plate")]
    assert spec.custom and spec.documentation == "plate"


def test_se016_fixes_the_weaker_layer_that_holds_the_mistake() -> None:
    rule = AttributeTypeMismatch()
    weaker = '#usda 1.0\nover "S"\n{\n    uniform float2 resolution = (10, 10)\n}\n'
    stage = stage_from_text(settings_layer("uniform int2 resolution = (1920, 1080)"), weaker)
    diagnostic = only(rule, stage)
    assert "hides it" in diagnostic.message
    layer = apply_fix(stage, diagnostic)
    assert layer != stage.GetRootLayer()
    assert layer.GetAttributeAtPath("/S.resolution").typeName == Sdf.ValueTypeNames.Int2
    assert attribute_value(stage, "resolution") == Gf.Vec2i(1920, 1080)
    assert diagnostics(rule, stage) == []


@pytest.mark.parametrize(
    "authored",
    [
        "uniform float2 resolution = (1920.5, 1080)",
        "uniform float3 resolution = (1920, 1080, 1)",
        'uniform string resolution = "1920x1080"',
    ],
)
def test_se016_offers_no_fix_when_the_value_would_change(authored: str) -> None:
    stage = stage_from_text(settings_layer(authored))
    assert only(AttributeTypeMismatch(), stage).fix is None
