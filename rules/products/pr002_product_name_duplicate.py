"""PR002 product-name-duplicate."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import (
    DEFAULT_TIME,
    PrimValues,
    composed_value,
    format_time,
    joint_evaluation_times,
    prim_values,
)


def _product_name(values: PrimValues, time: Usd.TimeCode) -> str:
    """productName of the product whose values are ``values`` at ``time``:
    authored, else the fallback; "" when mistyped."""
    if values.mismatched("productName") is not None:
        return ""
    if time is DEFAULT_TIME:  # the values hold it (composed_value's answer, without the lookup)
        return values.composed("productName") or ""
    return composed_value(values.prim, "productName", time) or ""


class ProductNameDuplicate(Rule):
    """Two products of one RenderSettings have the same productName.

    ## What it does
    For each RenderSettings, compares the `productName` of the usable
    RenderProducts its `products` targets (forwarded), at the default time and
    at every time where any of them has a time sample (capped). Two different
    products with the same non-empty name are reported once, on the second,
    at the first time they collide.

    ## Why is this bad?
    `productName` is *"used by render executables and pipeline tools to name
    the product, for example, using the productName as the filename (and
    path) for an output image artifact"* (RenderProduct prim definition,
    usd-core 26.11). Two products of one render writing the same file clobber
    each other.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel products = [</Render/Beauty>, </Render/Utility>]
        }

        def RenderProduct "Beauty"
        {
            token productName = "shot.exr"
        }

        def RenderProduct "Utility"
        {
            token productName = "shot.exr"
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
            rel products = [</Render/Beauty>, </Render/Utility>]
        }

        def RenderProduct "Beauty"
        {
            token productName = "shot_beauty.exr"
        }

        def RenderProduct "Utility"
        {
            token productName = "shot_utility.exr"
        }
    }
    ```

    ## Fix safety
    No automatic fix: which product should be renamed, and to what, is the
    author's choice.
    """

    code = "PR002"
    name = "product-name-duplicate"
    severity = Severity.ERROR
    partial_composition = True

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        reported: set[tuple[Sdf.Path, Sdf.Path]] = set()
        # The configurations already pair each settings with its usable products, in order.
        products_of: dict[int, list[Usd.Prim]] = {}
        for config in ctx.configurations:
            if config.settings is None:
                continue  # a product rendered on its own has no sibling products
            # Keyed by the handle: the configurations hold prims_of's own settings handles.
            products = products_of.setdefault(id(config.settings), [])
            if config.product is not None:
                products.append(config.product)
        for settings in ctx.prims_of(schemas.RenderSettings):
            products = products_of[id(settings)]
            product_values = [prim_values(product) for product in products]
            # Only an attribute that may have time samples adds evaluation times.
            attrs = [
                values.attribute("productName")
                for values in product_values
                if values.may_vary("productName")
            ]
            for time in joint_evaluation_times(attrs, ctx.time_sample_cap):
                owners: dict[str, Usd.Prim] = {}
                for product, values in zip(products, product_values, strict=True):
                    name = _product_name(values, time)
                    first = owners.setdefault(name, product)
                    if not name or first is product or first == product:
                        continue
                    # Paths are built only for a duplicate.
                    pair = (first.GetPath(), product.GetPath())
                    if pair in reported:
                        continue
                    reported.add(pair)
                    yield Diagnostic(
                        message=f"RenderProduct {product.GetPath()} has productName {name!r} at "
                        f"{format_time(time)}, like {first.GetPath()}: both are products of "
                        f"{settings.GetPath()} and write the same output; give each product "
                        "its own productName",
                        at=values.attribute("productName"),
                    )
