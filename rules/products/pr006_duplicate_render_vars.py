"""PR006 duplicate-render-vars."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import has_authored_value

from .._aov import checked_value, product_render_vars, targeted_vars

#: The schema attributes compared by value (fallbacks included).
_SOURCE = ("sourceType", "sourceName", "dataType")


def _source_key(ctx: Context, var: Usd.Prim) -> tuple[Any, ...]:
    """The var's source (``_SOURCE``), read once per lint: a dozen products
    share the same few vars."""
    return tuple(checked_value(var, n, ctx) for n in _SOURCE)


def _sources_may_repeat(ctx: Context) -> bool:
    """Whether two of the vars that products target have the same source: else
    no product's vars can (a product lists each forwarded target once), asked
    once per lint, not for every var of every product."""
    found = targeted_vars(ctx)
    if found is None:
        return True  # the vars are not known here: check each product
    keys = [ctx.cached(_source_key, var) for var in found]
    return len(set(keys)) < len(keys)


def _other_settings(ctx: Context, var: Usd.Prim) -> dict[str, Any]:
    """Every other attribute the var authors a well-typed value for (namespaced
    renderer settings such as ``arnold:filter`` or ``driver:parameters:aov:name``,
    custom attributes), by name: its default value and its time samples."""
    settings: dict[str, Any] = {}
    for attr in var.GetAuthoredAttributes():
        name = attr.GetName()
        if name in _SOURCE or not has_authored_value(attr):
            continue
        samples = tuple((t, attr.Get(t)) for t in attr.GetTimeSamples())
        settings[name] = (attr.Get(), samples)
    return settings


class DuplicateRenderVars(Rule):
    """Two RenderVars of one product are the same var: same source, same settings.

    ## What it does
    Reports two different usable RenderVar prims targeted by the same
    product's `orderedVars` whose composed `(sourceType, sourceName, dataType)`
    are identical **and** that author the same value for every other
    attribute (catalog R2-3): namespaced renderer settings such as
    `driver:parameters:aov:name`, `arnold:filter`, `ri:*` or `karma:*`, and
    custom attributes, compared by composed default value and time samples.
    An attribute only one of them authors makes them different vars. (The
    same path twice cannot occur: usd-core rejects duplicate targets in one
    list-op at parse time, and composed list-ops de-duplicate.) A var with an
    empty `sourceName` is left to VA001. Revision 1 compared the three source
    attributes alone and so reported, for example, arnold-usd's filtered and
    unfiltered beauty.

    ## Why is this bad?
    Each RenderVar is *"a quantity or 'channel' of computed data"* (RenderVar
    prim definition, usd-core 26.11): two vars computing the same thing
    produce a redundant channel, and, in renderers that name channels after
    `sourceName` for non-LPE vars (hdPrman's `_ComputeRenderViewDesc`,
    `third_party/renderman-26/plugin/hdPrman/renderParam.cpp`), a channel-name
    clash. Vars that differ in any other attribute are distinct channels:
    `UsdRenderComputeSpec` keeps those attributes as the var's
    `namespacedSettings` (`pxr/usd/usdRender/spec.cpp`) and renderers build
    their outputs from them (arnold-usd creates each var's pixel filter from
    its `arnold:filter` setting, `_CreateFilter` in
    `libs/render_delegate/render_pass.cpp`).

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = [</Render/Vars/color>, </Render/Vars/beauty>]
        }

        def Scope "Vars"
        {
            def RenderVar "color"
            {
                string sourceName = "Ci"
            }

            def RenderVar "beauty"
            {
                string sourceName = "Ci"
            }
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = [</Render/Vars/color>, </Render/Vars/alpha>]
        }

        def Scope "Vars"
        {
            def RenderVar "color"
            {
                string sourceName = "Ci"
            }

            def RenderVar "alpha"
            {
                token dataType = "float"
                string sourceName = "a"
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: which var to keep (and under which channel name) is the
    author's choice.
    """

    code = "PR006"
    name = "duplicate-render-vars"
    severity = Severity.WARNING
    partial_composition = True
    prim_types = (schemas.RenderProduct,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        if not ctx.cached(_sources_may_repeat):
            return  # no two targeted vars share a source (most stages)
        render_vars = product_render_vars(prim, ctx)
        keys = [ctx.cached(_source_key, var) for var in render_vars]
        if len(set(keys)) == len(keys):
            return  # no two vars share a source (most products): nothing to compare
        seen: dict[tuple, list[Usd.Prim]] = {}
        for var, key in zip(render_vars, keys, strict=True):
            if None in key or not key[1]:
                continue
            same_source = seen.setdefault(key, [])
            first = _same_var(same_source, var, ctx)
            same_source.append(var)
            if first is None:
                continue
            source_type, source_name, data_type = key
            others = sorted(ctx.cached(_other_settings, var))
            settings = f" and the same {', '.join(others)}" if others else ""
            yield Diagnostic(
                message=f"RenderVars {first.GetPath()} and {var.GetPath()} of {prim.GetPath()} "
                f"both compute sourceType {source_type!r}, sourceName {source_name!r}, dataType "
                f"{data_type!r}{settings}, and no other attribute tells them apart: a "
                "redundant channel; remove one from orderedVars or change its source or "
                "settings",
                at=prim.GetRelationship("orderedVars"),
            )


def _same_var(candidates: list[Usd.Prim], var: Usd.Prim, ctx: Context) -> Usd.Prim | None:
    """The first of ``candidates`` (vars with the same source) that authors the
    same other attributes as ``var``; those are read only for vars whose
    source collides."""
    if not candidates:
        return None
    settings = ctx.cached(_other_settings, var)
    return next((c for c in candidates if ctx.cached(_other_settings, c) == settings), None)
