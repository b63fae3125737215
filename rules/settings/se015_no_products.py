"""SE015 no-products."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values


class NoProducts(Rule):
    """A RenderSettings has no products, so the output is renderer-defined.

    ## What it does
    Reports a RenderSettings whose `products` has no forwarded target: the
    relationship is absent, authored empty, or emptied by list-op composition.

    ## Why is this bad?
    *"If no products are provided, renderers should render a default RGB
    image."* (`RenderSettings.md`). Valid, but the output's name and channels
    are then up to the renderer, which a farm submission rarely wants.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform int2 resolution = (1920, 1080)
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
            uniform int2 resolution = (1920, 1080)
            rel products = </Render/Beauty>
        }

        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
        }
    }
    ```

    ## Fix safety
    No automatic fix: the outputs are a pipeline decision.
    """

    code = "SE015"
    name = "no-products"
    severity = Severity.INFO
    partial_composition = True
    prim_types = (schemas.RenderSettings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        if values.forwarded("products"):
            return
        rel = values.relationship("products")
        authored = bool(rel) and rel.HasAuthoredTargets()
        state = "is empty" if authored else "is not authored"
        yield Diagnostic(
            message=f"RenderSettings {prim.GetPath()} has no products (products {state}); "
            "renderers "
            "then write a default RGB image with a name of their choosing: target the "
            "RenderProducts to write, e.g. rel products = </Render/Products/beauty>",
            at=rel if authored else prim,
        )
