"""PA001's fix: the relative-target pattern is retargeted, nothing else is."""

from __future__ import annotations

from pathlib import Path

from pxr import Sdf, Usd

from usdrender_lint.api import Context
from usdrender_lint.rules.passes.pa001_render_source_invalid import RenderSourceInvalid

HERE = Path(__file__).parent


def _diagnostics(stage: Usd.Stage, path: str):
    return list(RenderSourceInvalid().check_prim(stage.GetPrimAtPath(path), Context(stage, "x")))


def test_relative_target_is_rewritten_to_the_absolute_path() -> None:
    # An anonymous copy: editing the cached file layer would leak into other tests.
    stage = Usd.Stage.Open(Sdf.Layer.OpenAsAnonymous(str(HERE / "fail_relative_target.usda")))
    (diagnostic,) = _diagnostics(stage, "/Render/Passes/beauty")
    assert diagnostic.fix is not None and diagnostic.fix.safe
    diagnostic.fix.apply(stage)
    rel = stage.GetRelationshipAtPath("/Render/Passes/beauty.renderSource")
    assert rel.GetTargets() == [Sdf.Path("/Render/PrimarySettings")]
    assert _diagnostics(stage, "/Render/Passes/beauty") == []


def test_other_invalid_targets_have_no_fix() -> None:
    stage = Usd.Stage.Open(str(HERE / "fail_kinds.usda"))
    for path in ("/Render/Product", "/Render/Inactive", "/Render/NoSource"):
        (diagnostic,) = _diagnostics(stage, path)
        assert diagnostic.fix is None, path
