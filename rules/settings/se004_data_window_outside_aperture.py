"""SE004 data-window-outside-aperture."""

from __future__ import annotations

from collections.abc import Iterator

from usdrender_lint.api import Context, Diagnostic, Rule, Severity

from ._data_window import _well_formed_window_uses


class DataWindowOutsideAperture(Rule):
    """A well-formed dataWindowNDC lies entirely outside the camera aperture.

    ## What it does
    Reports an authored `dataWindowNDC` on a RenderSettings or RenderProduct
    that SE003 accepts but that does not overlap the unit square:
    `xmax <= 0`, `xmin >= 1`, `ymax <= 0` or `ymin >= 1`. A product no usable
    RenderSettings targets is checked on its own value (catalog R2-4). The
    check reads no camera attribute, so catalog R2-1's rendered times leave it
    at the default time, like every uniform render-prim attribute.

    ## Why is this bad?
    *"Specifying a window outside the unit square will produce overscan
    data."* (`RenderSettings.md`). A window that lies *entirely* outside
    renders nothing of the aperture: typically pixel coordinates or 0-100
    percentages typed as NDC.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform float4 dataWindowNDC = (1.1, 0, 1.3, 1)
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
            uniform float4 dataWindowNDC = (0.9, 0, 1.3, 1)
        }
    }
    ```

    ## Fix safety
    No automatic fix: the intended window cannot be guessed.
    """

    code = "SE004"
    name = "data-window-outside-aperture"
    severity = Severity.WARNING
    partial_composition = True

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for use in _well_formed_window_uses(ctx):
            xmin, ymin, xmax, ymax = use.values
            if xmax <= 0 or xmin >= 1 or ymax <= 0 or ymin >= 1:
                yield Diagnostic(
                    message=f"dataWindowNDC {use.text} does not overlap the camera aperture "
                    "(0, 0, 1, 1), so the image holds only overscan; NDC runs 0..1 across the "
                    "aperture: rescale pixel or percentage values, e.g. (0, 0, 1, 1)",
                    at=use.window.attr,
                )
