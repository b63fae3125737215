"""SE002 pixel-aspect-ratio-invalid."""

from __future__ import annotations

import math
from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values

from ._messages import _fmt


class PixelAspectRatioInvalid(Rule):
    """An authored pixelAspectRatio is zero, negative, NaN or infinite.

    ## What it does
    Checks an authored `pixelAspectRatio` (`float`, fallback `1.0`) on a
    RenderSettings or RenderProduct and fires when it is `<= 0` or not finite
    (usda accepts `nan` and `inf` literals).

    ## Why is this bad?
    *"The aspect ratio (width/height) of the rendered image pixels. … The
    resolution and pixel aspect ratio together determine the total aspect
    ratio of the rendered image."* (`RenderSettings.md`). `UsdRenderComputeSpec`
    returns early when the image aspect ratio is `<= 0`, leaving the aperture
    unconformed (`pxr/usd/usdRender/spec.cpp`).

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform float pixelAspectRatio = 0
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
            uniform float pixelAspectRatio = 1
        }
    }
    ```

    ## Fix safety
    No automatic fix. Deleting the opinion to fall back to 1.0 is suggested in
    the message, but an anamorphic squeeze may have been meant.
    """

    code = "SE002"
    name = "pixel-aspect-ratio-invalid"
    severity = Severity.ERROR
    partial_composition = True
    prim_types = (schemas.RenderSettingsBase,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        ratio = values.authored("pixelAspectRatio")
        if ratio is None or (math.isfinite(ratio) and ratio > 0):
            return
        yield Diagnostic(
            message=f"pixelAspectRatio is {_fmt(float(ratio))}; it must be a finite number > 0 "
            "(width/height of one pixel): author e.g. 1 for square pixels or 2 for a 2x "
            "anamorphic squeeze, or delete the opinion to get the fallback 1",
            at=values.attribute("pixelAspectRatio"),
        )
