"""PA006's fix: authors mode = "expression" in the expression's layer, only
when nothing says relationships were meant."""

from __future__ import annotations

from pathlib import Path

from pxr import Sdf, Usd

from usdrender_lint.api import Context
from usdrender_lint.rules.passes.pa006_collection_expression_ignored import (
    CollectionExpressionIgnored,
)

HERE = Path(__file__).parent


def _diagnostics(stage: Usd.Stage, path: str):
    rule = CollectionExpressionIgnored()
    return list(rule.check_prim(stage.GetPrimAtPath(path), Context(stage, "x")))


def test_fix_turns_expression_mode_on() -> None:
    # An anonymous copy: editing the cached file layer would leak into other tests.
    layer = Sdf.Layer.OpenAsAnonymous(str(HERE / "fail_include_root_fallback.usda"))
    stage = Usd.Stage.Open(layer)
    (diagnostic,) = _diagnostics(stage, "/Render/Passes/background")
    assert diagnostic.fix is not None and diagnostic.fix.safe
    assert diagnostic.fix.layer == layer
    diagnostic.fix.apply(stage)
    prim = stage.GetPrimAtPath("/Render/Passes/background")
    collection = Usd.CollectionAPI(prim, "renderVisibility")
    assert collection.IsInExpressionMode()
    assert not collection.ComputeMembershipQuery().IsPathIncluded("/World/characters")
    assert _diagnostics(stage, "/Render/Passes/background") == []


def test_fix_targets_the_layer_that_authors_the_expression() -> None:
    stage = Usd.Stage.Open(str(HERE / "fail_from_sublayer.usda"))
    (diagnostic,) = _diagnostics(stage, "/Render/background")
    assert diagnostic.fix.layer.identifier.endswith("expression_layer.usda")


def test_mixed_intent_has_no_fix() -> None:
    stage = Usd.Stage.Open(str(HERE / "fail_mixed_intent.usda"))
    for path in ("/Render/withIncludes", "/Render/explicitMode", "/Render/includeRootTrue"):
        (diagnostic,) = _diagnostics(stage, path)
        assert diagnostic.fix is None, path
