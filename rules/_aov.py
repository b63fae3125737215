"""What a RenderProduct outputs: its RenderVars and their channel names,
shared by the PR and VA rules."""

from __future__ import annotations

from typing import Any, Literal

from pxr import Usd

from usdrender_lint.api import Context, schemas
from usdrender_lint.api.resolve import PrimValues, Target, prim_values

#: How a renderer names a RenderVar's channel (catalog, Ambiguous semantics 7):
#: the schema says the prim name; hdPrman uses ``sourceName`` for non-LPE vars.
AovNaming = Literal["primName", "sourceName"]


def ordered_var_targets(product: Usd.Prim, ctx: Context) -> tuple[Target, ...]:
    """The product's forwarded ``orderedVars`` targets, resolved once per lint:
    PR005 checks each and :func:`product_render_vars` keeps the usable vars."""

    return prim_values(product).targets("orderedVars")


def product_render_vars(product: Usd.Prim, ctx: Context) -> tuple[Usd.Prim, ...]:
    """The usable RenderVar prims among the product's forwarded ``orderedVars``
    targets, in order (invalid targets are PR005's); read once per lint, as
    several PR and VA rules walk them."""

    return ctx.cached(_product_render_vars, product)


def _product_render_vars(ctx: Context, product: Usd.Prim) -> tuple[Usd.Prim, ...]:
    # One loop, no chain of generators: a CI-gate shot has 45 targets in 12 products.
    # Each target is judged once per lint, not once per product that lists it
    # (the 45 are 6 vars): resolve_target answers one Target per path.
    judged = ctx.cached(_judged_var_targets)
    found = []
    for target in ordered_var_targets(product, ctx):
        entry = judged.get(id(target))
        if entry is None:
            prim = target.prim
            # Usable (Target.usable_prim) and a RenderVar.
            usable = target.problem is None and prim is not None
            var = prim if usable and prim_values(prim).is_a(schemas.RenderVar) else None
            # The entry holds the target, so that its id is not reused.
            entry = judged[id(target)] = (target, var)
        if entry[1] is not None:
            found.append(entry[1])
    return tuple(found)


def _judged_var_targets(ctx: Context) -> dict[int, tuple[Target, Usd.Prim | None]]:
    """Filled by :func:`_product_render_vars`: an orderedVars target (by id)
    and its prim when it is a usable RenderVar."""
    return {}


def targeted_vars(ctx: Context) -> tuple[Usd.Prim, ...] | None:
    """The usable RenderVars that the usable products' forwarded ``orderedVars``
    target, each handle once, in first-target order; read once per lint. A dozen
    products target the same few vars: a question about every var of every
    product (VA008's channel names, PR006's sources) can be asked of these few.
    None when the context holds no walked products (a Context made by hand,
    whose ``check_prim`` callers pass products of their own): nothing is known."""
    return ctx.cached(_targeted_vars)


def _targeted_vars(ctx: Context) -> tuple[Usd.Prim, ...] | None:
    products = ctx.prims_of(schemas.RenderProduct)
    if not products:
        return None
    # By handle identity: each target path resolves to one handle per lint
    # (resolve_target), which the products' answers keep alive until it ends.
    # Two handles of one prim would both be listed: a repeat, never a miss.
    found: dict[int, Usd.Prim] = {}
    for product in products:
        for var in product_render_vars(product, ctx):
            found.setdefault(id(var), var)
    return tuple(found.values())


def checked_value(prim: Usd.Prim, name: str, ctx: Context) -> Any:
    """The composed value (authored or fallback), or None when the strongest
    opinion has the wrong type: that is SE016's finding, and a value rule must
    not add a second one for the same mistake. Read once per lint: most VA
    rules and several PR rules read the same few RenderVar attributes."""

    return checked(prim_values(prim), name)


def checked(values: PrimValues, name: str) -> Any:
    """:func:`checked_value` of the prim whose values a rule already holds."""
    if not values.may_be_authored(name):
        # No opinion to mistype: the schema's fallback (read once per definition).
        return values.fallback(name)
    return None if values.mismatched(name) is not None else values.composed(name)


def channel_name(var: Usd.Prim, naming: AovNaming, ctx: Context) -> str:
    """The channel name a renderer gives the var under ``naming``: the prim
    name, or (hdPrman) the prim name for LPE vars and ``sourceName`` otherwise."""
    if naming == "sourceName" and checked_value(var, "sourceType", ctx) != "lpe":
        return checked_value(var, "sourceName", ctx) or ctx.cached(_prim_name, var)
    return ctx.cached(_prim_name, var)


def _prim_name(ctx: Context, prim: Usd.Prim) -> str:
    """The prim's name, asked once per lint: VA008 names each var's channel
    for every product that targets it."""
    return Usd.Object.GetName(prim)  # unbound: no validity check of the (usable) var
