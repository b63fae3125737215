"""SE fixes: each ``apply`` edits the layer the fixer targets and silences the
rule; where the catalog's condition does not hold, no fix is offered."""

from __future__ import annotations

from collections.abc import Iterable

import pytest
from pxr import Gf, Sdf, Usd, UsdRender
from usdrender_lint.rules.settings.se006_aspect_ratio_conform_policy_invalid import (
    AspectRatioConformPolicyInvalid,
)
from usdrender_lint.rules.settings.se009_included_purposes_invalid import IncludedPurposesInvalid
from usdrender_lint.rules.settings.se010_included_purposes_missing_default import (
    IncludedPurposesMissingDefault,
)
from usdrender_lint.rules.settings.se011_material_binding_purposes_invalid import (
    MaterialBindingPurposesInvalid,
)
from usdrender_lint.rules.settings.se016_attribute_type_mismatch import AttributeTypeMismatch
from usdrender_lint.rules.settings.se017_time_samples_ignored import TimeSamplesIgnored

from usdrender_lint.api import Context, Diagnostic, Rule


def _stage(body: str, weaker: str | None = None) -> Usd.Stage:
    """An in-memory stage; ``weaker`` becomes a sublayer of the root layer."""
    root = Sdf.Layer.CreateAnonymous(".usda")
    root.ImportFromString("#usda 1.0\n" + body)
    if weaker is not None:
        sub = Sdf.Layer.CreateAnonymous(".usda")
        sub.ImportFromString("#usda 1.0\n" + weaker)
        root.subLayerPaths.append(sub.identifier)
    return Usd.Stage.Open(root)


def _diagnostics(rule: Rule, stage: Usd.Stage, cap: int = 1000) -> list[Diagnostic]:
    ctx = Context(stage=stage, file="memory.usda", time_sample_cap=cap)
    found: list[Diagnostic] = []
    for prim in stage.Traverse():
        if any(prim.IsA(schema) for schema in rule.prim_types):
            found.extend(rule.check_prim(prim, ctx))
    return found


def _strongest_layer(diagnostic: Diagnostic) -> Sdf.Layer:
    return diagnostic.layer or diagnostic.at.GetPropertyStack(Usd.TimeCode.Default())[0].layer


def _apply(stage: Usd.Stage, diagnostic: Diagnostic) -> Sdf.Layer:
    """What the fixer does: target the finding's layer, then apply."""
    layer = _strongest_layer(diagnostic)
    stage.SetEditTarget(Usd.EditTarget(layer))
    diagnostic.fix.apply(stage)
    return layer


def _only(diagnostics: Iterable[Diagnostic]) -> Diagnostic:
    (diagnostic,) = list(diagnostics)
    return diagnostic


def _settings(attrs: str) -> str:
    return 'def RenderSettings "S"\n{\n' + attrs + "\n}\n"


def _value(stage: Usd.Stage, name: str, path: str = "/S"):
    return stage.GetPrimAtPath(path).GetAttribute(name).Get()


# -- SE006 -------------------------------------------------------------------------


def test_se006_fixes_a_case_slip() -> None:
    rule = AspectRatioConformPolicyInvalid()
    stage = _stage(_settings('uniform token aspectRatioConformPolicy = "CROPAPERTURE"'))
    diagnostic = _only(_diagnostics(rule, stage))
    assert diagnostic.fix.safe
    _apply(stage, diagnostic)
    assert _value(stage, "aspectRatioConformPolicy") == "cropAperture"
    assert _diagnostics(rule, stage) == []


def test_se006_offers_no_fix_for_an_unknown_word() -> None:
    stage = _stage(_settings('uniform token aspectRatioConformPolicy = "fit"'))
    assert _only(_diagnostics(AspectRatioConformPolicyInvalid(), stage)).fix is None


# -- SE009, SE010, SE011 -------------------------------------------------------------


def test_se009_drops_repeats_keeping_order() -> None:
    rule = IncludedPurposesInvalid()
    stage = _stage(_settings('uniform token[] includedPurposes = ["render", "default", "render"]'))
    _apply(stage, _only(_diagnostics(rule, stage)))
    assert list(_value(stage, "includedPurposes")) == ["render", "default"]
    assert _diagnostics(rule, stage) == []


def test_se009_offers_no_fix_when_a_token_is_unknown() -> None:
    stage = _stage(
        _settings('uniform token[] includedPurposes = ["default", "preview", "preview"]')
    )
    assert _only(_diagnostics(IncludedPurposesInvalid(), stage)).fix is None


def test_se010_prepends_default_in_the_layer_that_authors_the_list() -> None:
    rule = IncludedPurposesMissingDefault()
    weaker = 'over "S"\n{\n    uniform token[] includedPurposes = ["render"]\n}\n'
    stage = _stage('def RenderSettings "S"\n{\n}\n', weaker)
    layer = _apply(stage, _only(_diagnostics(rule, stage)))
    assert layer != stage.GetRootLayer()
    edited = layer.GetAttributeAtPath("/S.includedPurposes").default
    assert list(edited) == ["default", "render"]
    assert not stage.GetRootLayer().GetAttributeAtPath("/S.includedPurposes")
    assert _diagnostics(rule, stage) == []


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
    stage = _stage(_settings(f"uniform token[] materialBindingPurposes = {authored}"))
    _apply(stage, _only(_diagnostics(rule, stage)))
    assert list(_value(stage, "materialBindingPurposes")) == fixed
    assert _diagnostics(rule, stage) == []


@pytest.mark.parametrize("authored", ['["render"]', "[]", '["full", "Preview"]'])
def test_se011_offers_no_fix_for_other_problems(authored: str) -> None:
    stage = _stage(_settings(f"uniform token[] materialBindingPurposes = {authored}"))
    assert _only(_diagnostics(MaterialBindingPurposesInvalid(), stage)).fix is None


# -- SE016 -------------------------------------------------------------------------


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
    stage = _stage(f'def {kind} "{path[1:]}"\n{{\n    {authored}\n}}\n')
    layer = _apply(stage, _only(_diagnostics(rule, stage)))
    spec = layer.GetAttributeAtPath(f"{path}.{name}")
    definition = stage.GetPrimAtPath(path).GetPrimDefinition().GetAttributeDefinition(name)
    assert spec.typeName == definition.GetTypeName()
    assert _value(stage, name, path) == expected
    assert _diagnostics(rule, stage) == []


def test_se016_converts_time_samples_and_keeps_variability() -> None:
    rule = AttributeTypeMismatch()
    stage = _stage(_settings("uniform float2 resolution.timeSamples = {1: (64, 32), 2: (128, 64)}"))
    layer = _apply(stage, _only(_diagnostics(rule, stage)))
    spec = layer.GetAttributeAtPath("/S.resolution")
    assert spec.variability == Sdf.VariabilityUniform
    assert layer.QueryTimeSample(spec.path, 2) == Gf.Vec2i(128, 64)
    assert isinstance(layer.QueryTimeSample(spec.path, 1), Gf.Vec2i)


def test_se016_fixes_the_weaker_layer_that_holds_the_mistake() -> None:
    rule = AttributeTypeMismatch()
    weaker = 'over "S"\n{\n    uniform float2 resolution = (10, 10)\n}\n'
    stage = _stage(_settings("uniform int2 resolution = (1920, 1080)"), weaker)
    diagnostic = _only(_diagnostics(rule, stage))
    assert "hides it" in diagnostic.message
    layer = _apply(stage, diagnostic)
    assert layer != stage.GetRootLayer()
    assert layer.GetAttributeAtPath("/S.resolution").typeName == Sdf.ValueTypeNames.Int2
    assert _value(stage, "resolution") == Gf.Vec2i(1920, 1080)
    assert _diagnostics(rule, stage) == []


@pytest.mark.parametrize(
    "authored",
    [
        "uniform float2 resolution = (1920.5, 1080)",
        "uniform float3 resolution = (1920, 1080, 1)",
        'uniform string resolution = "1920x1080"',
    ],
)
def test_se016_offers_no_fix_when_the_value_would_change(authored: str) -> None:
    stage = _stage(_settings(authored))
    assert _only(_diagnostics(AttributeTypeMismatch(), stage)).fix is None


# -- SE017 -------------------------------------------------------------------------


def test_se017_replaces_constant_samples_with_a_default() -> None:
    rule = TimeSamplesIgnored()
    stage = _stage(
        _settings("uniform int2 resolution.timeSamples = {1: (640, 480), 2: (640, 480)}")
    )
    _apply(stage, _only(_diagnostics(rule, stage)))
    attr = stage.GetPrimAtPath("/S").GetAttribute("resolution")
    assert attr.GetNumTimeSamples() == 0
    assert attr.Get() == Gf.Vec2i(640, 480)
    assert _diagnostics(rule, stage) == []


@pytest.mark.parametrize(
    "authored",
    [
        "uniform int2 resolution.timeSamples = {1: (640, 480), 2: (1280, 960)}",
        "uniform int2 resolution = (1, 1)\n    uniform int2 resolution.timeSamples = {1: (2, 2)}",
    ],
)
def test_se017_offers_no_fix_for_varying_or_conflicting_values(authored: str) -> None:
    stage = _stage(_settings(authored))
    assert _only(_diagnostics(TimeSamplesIgnored(), stage)).fix is None


def test_se017_offers_no_fix_beyond_the_time_sample_cap() -> None:
    # Samples past the cap are not read, so they cannot be known to be equal.
    stage = _stage(_settings("uniform int2 resolution.timeSamples = {1: (8, 8), 2: (8, 8)}"))
    assert _only(_diagnostics(TimeSamplesIgnored(), stage, cap=1)).fix is None
    assert _only(_diagnostics(TimeSamplesIgnored(), stage, cap=0)).fix is None


def test_se017_product_name_without_default_has_no_fix() -> None:
    stage = _stage(
        'def RenderProduct "P"\n{\n    token productName.timeSamples = {1: "a.exr"}\n}\n'
    )
    diagnostic = _only(_diagnostics(TimeSamplesIgnored(), stage))
    assert diagnostic.fix is None and "no default" in diagnostic.message


def test_render_prim_types_cover_every_render_schema() -> None:
    stage = _stage(
        'def RenderPass "Pass"\n{\n    uniform token passType.timeSamples = {1: "x"}\n}\n'
    )
    assert stage.GetPrimAtPath("/Pass").IsA(UsdRender.Pass)
    assert _only(_diagnostics(TimeSamplesIgnored(), stage)).fix is not None
