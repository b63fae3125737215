"""PR004 product-missing-render-vars."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values


class ProductMissingRenderVars(Rule):
    """A RenderProduct has no RenderVars in orderedVars.

    ## What it does
    Reports every usable RenderProduct, targeted by a RenderSettings or not,
    whose `orderedVars` has no forwarded target: the relationship is
    unauthored, authored empty, or emptied by list-op composition.

    ## Why is this bad?
    *"If products are provided, the products should be explicit about which
    RenderVars are needed."* (`RenderSettings.md`); *"A RenderProduct must also
    specify one or more RenderVars"* (`pxr/usd/usdRender/userDoc/overview.md`).
    The product reaches the renderer with zero channels: at best an empty file.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel products = </Render/Beauty>
        }

        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel products = </Render/Beauty>
        }

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
    No automatic fix: which outputs a product needs is a pipeline decision.
    """

    code = "PR004"
    name = "product-missing-render-vars"
    severity = Severity.ERROR
    partial_composition = True
    prim_types = (schemas.RenderProduct,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        if values.forwarded("orderedVars"):
            return
        rel = values.relationship("orderedVars")
        state = "is empty" if rel and rel.HasAuthoredTargets() else "is not authored"
        yield Diagnostic(
            message=f"RenderProduct {prim.GetPath()} has no RenderVars: orderedVars {state}; "
            "target "
            "the RenderVars this output needs, e.g. rel orderedVars = [</Render/Vars/color>]",
            at=rel if rel and rel.HasAuthoredTargets() else prim,
        )
