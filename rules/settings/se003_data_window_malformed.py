"""SE003 data-window-malformed."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity
from usdrender_lint.api.resolve import is_finite

from ._data_window import _data_window_problem, _window_uses
from ._fixes import Apply


def _swap_x(attr_path: Sdf.Path) -> Apply:
    def apply(stage: Usd.Stage) -> None:
        attr = stage.GetAttributeAtPath(attr_path)
        xmin, ymin, xmax, ymax = attr.Get()
        attr.Set(type(attr.Get())(xmax, ymin, xmin, ymax))

    return apply


class DataWindowMalformed(Rule):
    """An authored dataWindowNDC is non-finite, inverted, empty or covers no pixel.

    ## What it does
    Checks each authored `dataWindowNDC` `(xmin, ymin, xmax, ymax)` on a
    RenderSettings or RenderProduct, with the resolution of the render
    configuration it is used in (a product's authored `resolution`, else its
    settings'; for a product no usable settings targets, its own value or the
    fallback, catalog R2-4). It is malformed when a component is NaN or infinite, when
    `xmin >= xmax` or `ymin >= ymax`, or when it contains no pixel centre: the
    centre of pixel *i* is at `(i + 0.5) / W`, the minimum edge inclusive and
    the maximum edge exclusive.

    ## Why is this bad?
    *"Specified as (xmin, ymin, xmax, ymax) in normalized device coordinates
    (NDC), where the range 0 to 1 corresponds to the aperture."* and *"A pixel
    is included in the rendered result if the pixel center is contained by the
    data window."* (`RenderSettings.md`). An inverted window gives an empty
    `GfRange2f` in `UsdRenderComputeSpec`: the render is an empty image.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform float4 dataWindowNDC = (0.8, 0, 0.2, 1)
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
            uniform float4 dataWindowNDC = (0.2, 0, 0.8, 1)
        }
    }
    ```

    ## Fix safety
    Unsafe: when only x is inverted with finite values, the fix swaps `xmin`
    and `xmax`; the intent could instead have been a typo in one value.
    """

    code = "SE003"
    name = "data-window-malformed"
    severity = Severity.ERROR
    partial_composition = True
    fix_safety = "unsafe"

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        # A window's problem, by its attribute handle (one per prim and name in
        # a lint): a malformed window is malformed at every resolution it is
        # used at, and the finding is made once (the engine kept one of them).
        reported: set[tuple[int, str]] = set()
        for use in _window_uses(ctx):
            window = use.window
            problem = _data_window_problem(window.value, use.resolution)
            if problem is None or (id(window.attr), problem) in reported:
                continue
            reported.add((id(window.attr), problem))
            xmin, _, xmax, _ = window.value
            fix = None
            if "inverted" in problem and is_finite(window.value) and xmin > xmax:
                fix = Fix(
                    description="swap xmin and xmax",
                    safe=False,
                    apply=_swap_x(window.attr.GetPath()),
                )
            yield Diagnostic(
                message=f"dataWindowNDC {use.text} {problem}; "
                "use (xmin, ymin, xmax, ymax) with min < max, e.g. (0, 0, 1, 1)",
                at=window.attr,
                fix=fix,
            )
