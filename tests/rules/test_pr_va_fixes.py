"""The fixes the PR and VA rules offer: applied to the layer holding the
offending opinion, each one silences its rule and authors the intended value."""

from __future__ import annotations

from pathlib import Path

import pytest
from pxr import Sdf, Usd

from usdrender_lint.api import Context, Rule
from usdrender_lint.config import ConfigError, read_config_file
from usdrender_lint.registry import build_registry
from usdrender_lint.rules import products, vars
from usdrender_lint.running.pipeline import make_rules

STAGE = """#usda 1.0

def Scope "Render"
{
    def RenderProduct "Beauty"
    {
        uniform token productType = "DeepRaster"
        rel orderedVars = [</Render/Vars/color>, </Render/Vars/gone>]
    }

    def Scope "Vars"
    {
        def RenderVar "color"
        {
            string sourceName = "lpe:C.*"
            uniform token sourceType = "LPE"
        }

        def RenderVar "direct"
        {
            string sourceName = "lpe:C<RD>L"
            uniform token sourceType = "lpe"
        }

        def RenderVar "depth"
        {
            uniform token dataType = "Float"
            string sourceName = "z"
        }

        def RenderVar "samples"
        {
            uniform token dataType = "float[]"
            string sourceName = "samples"
        }

        def RenderVar "alpha"
        {
            string sourceName = "a"
        }

        def RenderVar "id"
        {
            string sourceName = "primId"
        }
    }
}
"""

CASES = [
    (products.ProductTypeNotAllowed, "/Render/Beauty", "productType", "deepRaster", True),
    (
        products.OrderedVarsInvalidTarget,
        "/Render/Beauty",
        "orderedVars",
        [Sdf.Path("/Render/Vars/color")],
        False,
    ),
    (vars.SourceTypeNotAllowed, "/Render/Vars/color", "sourceType", "lpe", True),
    (vars.LpeMalformed, "/Render/Vars/direct", "sourceName", "C<RD>L", True),
    (vars.DataTypeUnknown, "/Render/Vars/depth", "dataType", "float", True),
    (vars.DataTypeNotPixelType, "/Render/Vars/samples", "dataType", "float", False),
    (vars.ScalarSourceDefaultColor3f, "/Render/Vars/alpha", "dataType", "float", True),
    (vars.ScalarSourceDefaultColor3f, "/Render/Vars/id", "dataType", "int", True),
]


def _diagnostics(rule: Rule, stage: Usd.Stage, prim_path: str):
    return list(rule.check_prim(stage.GetPrimAtPath(prim_path), Context(stage, "fixture")))


@pytest.mark.parametrize(
    ("rule_class", "prim_path", "prop", "expected", "safe"),
    CASES,
    ids=lambda v: getattr(v, "code", None),
)
def test_fix_applies(tmp_path: Path, rule_class, prim_path, prop, expected, safe) -> None:
    path = tmp_path / "stage.usda"
    path.write_text(STAGE, encoding="utf-8")
    stage = Usd.Stage.Open(str(path))
    rule = rule_class()
    (diagnostic,) = _diagnostics(rule, stage, prim_path)
    assert diagnostic.fix is not None and diagnostic.fix.safe is safe
    stage.SetEditTarget(stage.GetRootLayer())
    diagnostic.fix.apply(stage)
    prop_obj = stage.GetPrimAtPath(prim_path).GetProperty(prop)
    value = prop_obj.GetTargets() if prop == "orderedVars" else prop_obj.Get()
    assert value == expected
    assert _diagnostics(rule, stage, prim_path) == []


def test_no_fix_when_the_intent_is_unclear(tmp_path: Path) -> None:
    path = tmp_path / "unclear.usda"
    path.write_text(
        STAGE.replace('"DeepRaster"', '"exr"')
        .replace('"Float"', '"rgb"')
        .replace('"float[]"', '"string"')
        .replace('"a"', '"mask"'),
        encoding="utf-8",
    )
    stage = Usd.Stage.Open(str(path))
    for rule, prim_path in [
        (products.ProductTypeNotAllowed(), "/Render/Beauty"),
        (vars.DataTypeUnknown(), "/Render/Vars/depth"),
        (vars.DataTypeNotPixelType(), "/Render/Vars/samples"),
        (vars.ScalarSourceDefaultColor3f(), "/Render/Vars/alpha"),
    ]:
        (diagnostic,) = _diagnostics(rule, stage, prim_path)
        assert diagnostic.fix is None, rule.code


# -- fixes a pipeline configures (PR001 name template, PR008 default alpha var) ----

PIPELINE = """#usda 1.0

def Scope "Render"
{
    def RenderProduct "Deep"
    {
        uniform token productType = "deepRaster"
        rel orderedVars = </Render/Vars/color>
    }

    def Scope "Vars"
    {
        def RenderVar "color"
        {
            string sourceName = "Ci"
        }

        def RenderVar "alpha"
        {
            uniform token dataType = "float"
            string sourceName = "a"
        }
    }
}
"""


def _pipeline_stage(tmp_path: Path) -> Usd.Stage:
    path = tmp_path / "pipeline.usda"
    path.write_text(PIPELINE, encoding="utf-8")
    stage = Usd.Stage.Open(str(path))
    stage.SetEditTarget(stage.GetRootLayer())
    return stage


def test_no_pipeline_fix_by_default(tmp_path: Path) -> None:
    stage = _pipeline_stage(tmp_path)
    for rule in (products.ProductNameEmpty(), products.DeepRasterMissingAlpha()):
        (diagnostic,) = _diagnostics(rule, stage, "/Render/Deep")
        assert diagnostic.fix is None


def test_name_template_fix(tmp_path: Path) -> None:
    stage = _pipeline_stage(tmp_path)
    rule = products.ProductNameEmpty(products.ProductNameEmpty.Options("shots/{prim}.exr"))
    (diagnostic,) = _diagnostics(rule, stage, "/Render/Deep")
    diagnostic.fix.apply(stage)
    assert stage.GetAttributeAtPath("/Render/Deep.productName").Get() == "shots/Deep.exr"
    assert _diagnostics(rule, stage, "/Render/Deep") == []


def test_default_alpha_var_fix(tmp_path: Path) -> None:
    stage = _pipeline_stage(tmp_path)
    rule = products.DeepRasterMissingAlpha(
        products.DeepRasterMissingAlpha.Options("/Render/Vars/alpha")
    )
    (diagnostic,) = _diagnostics(rule, stage, "/Render/Deep")
    diagnostic.fix.apply(stage)
    targets = stage.GetRelationshipAtPath("/Render/Deep.orderedVars").GetTargets()
    assert targets == [Sdf.Path("/Render/Vars/color"), Sdf.Path("/Render/Vars/alpha")]
    assert _diagnostics(rule, stage, "/Render/Deep") == []


@pytest.mark.parametrize("alpha_var", ["/Render/Vars/color", "/Render/Vars/none", "not a path"])
def test_no_alpha_fix_when_the_configured_var_is_unusable(tmp_path: Path, alpha_var) -> None:
    stage = _pipeline_stage(tmp_path)
    rule = products.DeepRasterMissingAlpha(products.DeepRasterMissingAlpha.Options(alpha_var))
    (diagnostic,) = _diagnostics(rule, stage, "/Render/Deep")
    assert diagnostic.fix is None


@pytest.mark.parametrize(
    "table",
    [
        "[rules.PR001]\nname-template = 3\n",
        '[rules.PR001]\ntemplate = "{prim}.exr"\n',
        '[rules.PR008]\nalpha-var = ["/Render/Vars/alpha"]\n',
    ],
)
def test_bad_pipeline_options_are_config_errors(tmp_path: Path, table: str) -> None:
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text(table, encoding="utf-8")
    with pytest.raises(ConfigError, match="PR00"):
        make_rules(build_registry(), read_config_file(config))
