"""KA001 karma-product-not-written."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import authored_value

from ._husk import NOT_WRITTEN


class ProductNotWritten(Rule):
    """A RenderProduct's productName tells husk to write no file.

    ## What it does
    Under the `karma` profile, reports a RenderProduct whose authored
    `productName` (at the default time or any time sample) is
    `husk:null_raster` or `ip`.

    ## Why is this bad?
    *"If a render product name is set to husk:null_raster, husk will render
    the image, but no image will be saved to disk."* (Houdini docs, husk,
    https://www.sidefx.com/docs/houdini/ref/utils/husk.html), and `ip` sends
    the image to MPlay instead of a file (Houdini docs, Karma Render Settings
    LOP, Output Picture). Both are debugging settings: a farm job with them
    spends its render time and leaves no image.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            int karma:global:samplesperpixel = 9
            rel products = </Render/Beauty>
        }

        def RenderProduct "Beauty"
        {
            token productName = "husk:null_raster"
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
            int karma:global:samplesperpixel = 9
            rel products = </Render/Beauty>
        }

        def RenderProduct "Beauty"
        {
            token productName = "beauty.$F4.exr"
        }
    }
    ```

    ## Fix safety
    No automatic fix: only the pipeline knows where the image belongs.
    """

    code = "KA001"
    name = "karma-product-not-written"
    severity = Severity.WARNING
    partial_composition = True
    profile = "karma"
    prim_types = (schemas.RenderProduct,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("productName")
        values = [authored_value(attr)]
        values += [attr.Get(t) for t in attr.GetTimeSamples()[: ctx.time_sample_cap]]
        for value in values:
            effect = NOT_WRITTEN.get(str(value)) if value is not None else None
            if effect:
                yield Diagnostic(
                    message=f"productName {str(value)!r} of {prim.GetPath()}: {effect}; "
                    "author the image file to write, e.g. token productName = "
                    f'"{prim.GetName()}.$F4.exr"',
                    at=attr,
                )
                return
