"""SE005 data-window-crop-or-overscan."""

from __future__ import annotations

from collections.abc import Iterator

from usdrender_lint.api import Context, Diagnostic, Rule, Severity
from usdrender_lint.api.raster import pixel_span

from ._data_window import _well_formed_window_uses


class DataWindowCropOrOverscan(Rule):
    """A dataWindowNDC crops the aperture or renders overscan.

    ## What it does
    Reports an authored, well-formed `dataWindowNDC` that overlaps the unit
    square but differs from `(0, 0, 1, 1)`: *cropped* when `xmin > 0`,
    `ymin > 0`, `xmax < 1` or `ymax < 1`; *overscan* when a bound lies outside
    the unit square (both may apply). The message gives the pixel data window
    at the configuration's resolution (for a product no usable RenderSettings
    targets, its own or the fallback, catalog R2-4). The check reads no camera
    attribute, so catalog R2-1's rendered times leave it at the default time.

    ## Why is this bad?
    *"Specifying a window outside the unit square will produce overscan data.
    Specifying a window that does not cover the unit square will produce a
    cropped render."* (`RenderSettings.md`). Legitimate for tiling or comp
    margins, but a crop left over from an interactive session is a classic
    farm mistake, so it is surfaced as information.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform float4 dataWindowNDC = (-0.05, -0.05, 1.05, 1.05)
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
            uniform float4 dataWindowNDC = (0, 0, 1, 1)
        }
    }
    ```

    ## Fix safety
    No automatic fix: a crop or an overscan margin may be intended.
    """

    code = "SE005"
    name = "data-window-crop-or-overscan"
    severity = Severity.INFO
    partial_composition = True

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for use in _well_formed_window_uses(ctx):
            xmin, ymin, xmax, ymax = use.values
            if xmax <= 0 or xmin >= 1 or ymax <= 0 or ymin >= 1:
                continue  # SE004's finding
            kinds = []
            if xmin > 0 or ymin > 0 or xmax < 1 or ymax < 1:
                kinds.append("crops")
            if xmin < 0 or ymin < 0 or xmax > 1 or ymax > 1:
                kinds.append("adds overscan to")
            if not kinds:
                continue
            width, height = int(use.resolution[0]), int(use.resolution[1])
            pixels = ""
            if width > 0 and height > 0:  # else SE001's finding: there are no pixels
                x0, x1 = pixel_span(xmin, xmax, width)
                y0, y1 = pixel_span(ymin, ymax, height)
                pixels = (
                    f": pixels x {x0}..{x1 - 1}, y {y0}..{y1 - 1} of the {width}x{height} "
                    f"aperture (0..{width - 1}, 0..{height - 1})"
                )
            yield Diagnostic(
                message=f"dataWindowNDC {use.text} {' and '.join(kinds)} the image{pixels}; "
                "if unintended, remove the opinion or author (0, 0, 1, 1)",
                at=use.window.attr,
            )
