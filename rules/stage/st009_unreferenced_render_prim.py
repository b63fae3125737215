"""ST009 unreferenced-render-prim."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import UsdRender

from usdrender_lint.api import Context, Diagnostic, Rule, Severity
from usdrender_lint.api.resolve import forwarded_targets


class UnreferencedRenderPrim(Rule):
    """A RenderProduct or RenderVar that nothing renders.

    ## What it does
    Reports a usable RenderProduct that is not among the forwarded `products`
    targets of any RenderSettings, and a usable RenderVar that is not among the
    forwarded `orderedVars` targets of any RenderProduct.

    ## Why is this bad?
    `UsdRenderComputeSpec` reaches products only through
    `settings.GetProductsRel().GetForwardedTargets()` and vars only through
    `GetOrderedVarsRel()` (`pxr/usd/usdRender/spec.cpp`): orphans are dead data
    and usually mean a renamed or forgotten connection.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
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
        }
    }
    ```

    ## Fix safety
    No automatic fix: another settings layer may still want the prim.
    """

    code = "ST009"
    name = "unreferenced-render-prim"
    severity = Severity.INFO
    partial_composition = True

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for product in ctx.untargeted_products:
            yield Diagnostic(
                message=f"RenderProduct <{product.GetPath()}> is in no RenderSettings' products, "
                "so "
                "nothing renders it; add it to a RenderSettings' products or remove it",
                at=product,
            )
        targeted = {
            path
            for product in ctx.prims_of(UsdRender.Product)
            for path in forwarded_targets(product.GetRelationship("orderedVars"))
        }
        for var in ctx.prims_of(UsdRender.Var):
            if var.GetPath() not in targeted:
                yield Diagnostic(
                    message=f"RenderVar <{var.GetPath()}> is in no RenderProduct's orderedVars, so "
                    "no product outputs it; add it to a product's orderedVars or remove it",
                    at=var,
                )
