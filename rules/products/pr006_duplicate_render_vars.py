"""PR006 duplicate-render-vars."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd, UsdRender

from usdrender_lint.api import Context, Diagnostic, Rule, Severity

from .._aov import checked_value, product_render_vars


class DuplicateRenderVars(Rule):
    """Two RenderVars of one product compute the same source.

    ## What it does
    Reports two different usable RenderVar prims targeted by the same
    product's `orderedVars` whose composed `(sourceType, sourceName, dataType)`
    are identical. (The same path twice cannot occur: usd-core rejects duplicate
    targets in one list-op at parse time, and composed list-ops de-duplicate.)
    A var with an empty `sourceName` is left to VA001.

    ## Why is this bad?
    Each RenderVar is *"a quantity or 'channel' of computed data"* (RenderVar
    prim definition, usd-core 26.11): two vars computing the same source
    produce a redundant channel, and, in renderers that name channels after
    `sourceName` for non-LPE vars (hdPrman's `_ComputeRenderViewDesc`,
    `third_party/renderman-26/plugin/hdPrman/renderParam.cpp`), a channel-name
    clash.

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
    prim_types = (UsdRender.Product,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        seen: dict[tuple, Usd.Prim] = {}
        for var in product_render_vars(prim, ctx):
            key = tuple(
                checked_value(var, n, ctx) for n in ("sourceType", "sourceName", "dataType")
            )
            if None in key or not key[1]:
                continue
            first = seen.setdefault(key, var)
            if first == var:  # the same prim (Usd.Prim equality), without building paths
                continue
            source_type, source_name, data_type = key
            yield Diagnostic(
                message=f"RenderVars {first.GetPath()} and {var.GetPath()} of {prim.GetPath()} "
                "both "
                f"compute sourceType {source_type!r}, sourceName {source_name!r}, dataType "
                f"{data_type!r}: a redundant channel; remove one from orderedVars or change "
                "its source",
                at=UsdRender.Product(prim).GetOrderedVarsRel(),
            )
