"""PR003 product-type-not-allowed."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values

from .._corrections import set_value, unique_case_match


def _renderer_product_type(prim: Usd.Prim) -> str | None:
    """An authored ``<renderer>:productType`` override, the schema-sanctioned
    way to ask for a custom output type (catalog, Ambiguous semantics 14)."""
    for attr in prim.GetAuthoredAttributes():
        if attr.GetName().endswith(":productType") and attr.HasAuthoredValue():
            return attr.GetName()
    return None


class ProductTypeNotAllowed(Rule):
    """A RenderProduct's productType is not raster or deepRaster.

    ## What it does
    Reports an authored `productType` that is not one of the schema's
    `allowedTokens` (`raster`, `deepRaster`), unless the product also has an
    authored renderer-specific override attribute whose name ends in
    `:productType` (e.g. `ri:productType`).

    ## Why is this bad?
    `allowedTokens = ["raster", "deepRaster"]` and *"Renderers that support
    custom output types are encouraged to supply an applied API schema that
    will add an `token myRenderContext:productType` attribute (e.g. `token
    ri:productType`), which will override this attribute's value for that
    renderer."* (`pxr/usd/usdRender/schema.usda`). A file format such as `exr`
    in `productType` is a common confusion with `productName`.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            uniform token productType = "exr"
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
            uniform token productType = "raster"
        }
    }
    ```

    ## Fix safety
    Safe, conditional: a value that differs from an allowed token only in case
    (`DeepRaster`) is corrected to it (`deepRaster`); otherwise there is no
    fix.
    """

    code = "PR003"
    name = "product-type-not-allowed"
    severity = Severity.WARNING
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = (schemas.RenderProduct,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        value = values.authored("productType")
        if value is None:
            return
        allowed = values.schema_attribute("productType").allowed_tokens
        if value in allowed or _renderer_product_type(prim):
            return
        attr = values.attribute("productType")
        if ctx.profile_accepts(attr, "product_type", value):
            return  # a product type the renderer itself writes (R2-5)
        renderer_types = ctx.accepted_names(attr, "product_types")
        correction = unique_case_match(value, allowed)
        if correction:
            advice = f"did you mean {correction!r}?"
        else:
            advice = (
                f"use {' or '.join(allowed)} (a file format belongs in productName), or author "
                "a renderer-specific override such as ri:productType"
            )
        choices = ", ".join([*allowed, *renderer_types])
        yield Diagnostic(
            message=f"productType {value!r} of {prim.GetPath()} is not one of {choices}; " + advice,
            at=attr,
            fix=Fix(
                description=f"set productType to {correction!r}",
                safe=True,
                apply=set_value(attr.GetPath(), correction),
            )
            if correction
            else None,
        )
