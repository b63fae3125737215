"""What a RenderProduct outputs: its RenderVars and their channel names,
shared by the PR and VA rules."""

from __future__ import annotations

from typing import Any, Literal

from pxr import Usd, UsdRender

from usdrender_lint.resolve import composed_value, mismatched_spec, resolve_targets

#: How a renderer names a RenderVar's channel (catalog, Ambiguous semantics 7):
#: the schema says the prim name; hdPrman uses ``sourceName`` for non-LPE vars.
AovNaming = Literal["primName", "sourceName"]


def product_render_vars(product: Usd.Prim) -> list[Usd.Prim]:
    """The usable RenderVar prims among the product's forwarded ``orderedVars``
    targets, in order (invalid targets are PR005's)."""
    rel = UsdRender.Product(product).GetOrderedVarsRel()
    return [t.prim for t in resolve_targets(rel) if t.ok and t.prim.IsA(UsdRender.Var)]


def checked_value(prim: Usd.Prim, name: str) -> Any:
    """The composed value (authored or fallback), or None when the strongest
    opinion has the wrong type: that is SE016's finding, and a value rule must
    not add a second one for the same mistake."""
    if mismatched_spec(prim.GetAttribute(name)) is not None:
        return None
    return composed_value(prim, name)


def channel_name(var: Usd.Prim, naming: AovNaming) -> str:
    """The channel name a renderer gives the var under ``naming``: the prim
    name, or (hdPrman) the prim name for LPE vars and ``sourceName`` otherwise."""
    if naming == "sourceName" and checked_value(var, "sourceType") != "lpe":
        return checked_value(var, "sourceName") or var.GetName()
    return var.GetName()
