"""ST009 unreferenced-render-prim."""

from __future__ import annotations

from collections.abc import Iterator

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import renders_on_its_own, values_in

from .._aov import targeted_vars


class UnreferencedRenderPrim(Rule):
    """A RenderProduct or RenderVar that no RenderSettings or product reaches.

    ## What it does
    Reports a usable RenderProduct that is not among the forwarded `products`
    targets of any usable RenderSettings, and a usable RenderVar that is not
    among the forwarded `orderedVars` targets of any RenderProduct. A product
    that authors its own camera is still reported, but since catalog Revision 2
    (R2-4) it is also checked as a render configuration of its own (the CA and
    data-window rules), and the message says so.

    ## Why is this bad?
    `UsdRenderComputeSpec` reaches products only through
    `settings.GetProductsRel().GetForwardedTargets()` and vars only through
    `GetOrderedVarsRel()` (`pxr/usd/usdRender/spec.cpp`): orphans are dead data
    to it and usually mean a renamed or forgotten connection. Some renderers
    render a product directly by its prim path (ovrtx, Kit's render products;
    catalog R2-4), so an orphan product with a camera may be intended.

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
            if renders_on_its_own(product):
                effect = (
                    "so UsdRenderComputeSpec never renders it; renderers that render products "
                    "by prim path render it on its own camera and values, which are checked as "
                    "a configuration of their own"
                )
            else:
                effect = "so nothing renders it"
            yield Diagnostic(
                message=f"RenderProduct <{product.GetPath()}> is in no RenderSettings' products, "
                f"{effect}; add it to a RenderSettings' products or remove it",
                at=product,
            )
        # By the targets' PrimValues (one per prim in a lint, whichever handle
        # asks): no path is hashed or compared, each a call into USD. A usable
        # RenderVar that a product targets is one of its usable RenderVar
        # targets: the few distinct ones, not every target of every product.
        targeted = {id(values_in(ctx.cache, var)) for var in targeted_vars(ctx) or ()}
        for var in ctx.prims_of(schemas.RenderVar):
            if id(values_in(ctx.cache, var)) not in targeted:
                yield Diagnostic(
                    message=f"RenderVar <{var.GetPath()}> is in no RenderProduct's orderedVars, so "
                    "no product outputs it; add it to a product's orderedVars or remove it",
                    at=var,
                )
