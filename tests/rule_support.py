"""Helpers the per-rule tests share: a stage from usda text in memory, one
rule's diagnostics on it (as the engine's walk gives them, Fix objects
included), and a fix applied where the fixer would apply it."""

from __future__ import annotations

from typing import Any

import pytest
from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, resolve
from usdrender_lint.engine import RENDER_SCHEMAS

#: A stage with one RenderSettings, </Render/Settings>, and no metadata.
ONE_SETTINGS = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
    }
}
"""


def _layer(text: str) -> Sdf.Layer:
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(text)
    return layer


def stage_from_text(text: str, *sublayers: str, session: str | None = None) -> Usd.Stage:
    """An in-memory stage from usda text (header included); ``sublayers`` are
    the root layer's subLayers, strongest first, ``session`` the session layer."""
    root = _layer(text)
    # Anonymous layers live only while referenced: hold them until the stage does.
    weaker = [_layer(sublayer) for sublayer in sublayers]
    root.subLayerPaths = [layer.identifier for layer in weaker]
    if session is None:
        return Usd.Stage.Open(root)
    return Usd.Stage.Open(root, _layer(session))


def _context(stage: Usd.Stage, cap: int) -> Context:
    """What the engine's walk gives the rules (render prims, unknown types)."""
    ctx = Context(stage=stage, file="memory.usda", time_sample_cap=cap)
    for prim in stage.Traverse():
        for schema in RENDER_SCHEMAS:
            if prim.IsA(schema):
                ctx.render_prims.setdefault(schema, []).append(prim)
        if prim.GetTypeName() and prim.GetPrimTypeInfo().GetSchemaType().isUnknown:
            ctx.unknown_type_prims.append(prim)
    return ctx


def diagnostics(rule: Rule, stage: Usd.Stage, cap: int = 1000) -> list[Diagnostic]:
    """``rule``'s check_stage and check_prim diagnostics on ``stage``."""
    ctx = _context(stage, cap)
    found = list(rule.check_stage(ctx))
    for prim in stage.Traverse():
        if any(prim.IsA(schema) for schema in rule.prim_types):
            found.extend(rule.check_prim(prim, ctx))
    return found


def only(rule: Rule, stage: Usd.Stage, cap: int = 1000) -> Diagnostic:
    """The one diagnostic ``rule`` gives on ``stage`` (fails on none or more)."""
    (diagnostic,) = diagnostics(rule, stage, cap)
    return diagnostic


def _target_layer(stage: Usd.Stage, diagnostic: Diagnostic, fix: Fix) -> Sdf.Layer:
    """The fixer's choice: the fix's layer, else the finding's, else the
    strongest opinion on ``at``, else the root layer."""
    if fix.layer is not None:
        return fix.layer
    if diagnostic.layer is not None:
        return diagnostic.layer
    at = diagnostic.at
    if isinstance(at, Usd.Property):
        return at.GetPropertyStack(Usd.TimeCode.Default())[0].layer
    if isinstance(at, Usd.Prim):
        return at.GetPrimStack()[0].layer
    return stage.GetRootLayer()


def apply_fix(stage: Usd.Stage, diagnostic: Diagnostic) -> Sdf.Layer:
    """Apply the diagnostic's fix in the layer the fixer targets; that layer."""
    fix = diagnostic.fix
    assert fix is not None, f"no fix offered: {diagnostic.message}"
    layer = _target_layer(stage, diagnostic, fix)
    stage.SetEditTarget(Usd.EditTarget(layer))
    fix.apply(stage)
    return layer


def settings_layer(attributes: str) -> str:
    """A layer with one RenderSettings </S> holding ``attributes`` (usda lines)."""
    return '#usda 1.0\ndef RenderSettings "S"\n{\n' + attributes + "\n}\n"


def attribute_value(stage: Usd.Stage, name: str, path: str = "/S"):
    return stage.GetPrimAtPath(path).GetAttribute(name).Get()


def patch_usd(monkeypatch: pytest.MonkeyPatch, owner: type, method: str, replacement: Any) -> None:
    """Replace a USD method on its class and wherever resolve holds it unbound
    (its module constants skip Usd.Object's attribute lookup), so a spy sees
    every call."""
    original = getattr(owner, method)
    monkeypatch.setattr(owner, method, replacement)
    for name, held in vars(resolve).items():
        if held is original:
            monkeypatch.setattr(resolve, name, replacement)
