"""CA009 clipping-range-invalid."""

from __future__ import annotations

from collections.abc import Iterator

from usdrender_lint.api import Context, Diagnostic, Rule, Severity
from usdrender_lint.api.resolve import is_finite

from .._camera import at_time, effective_cameras, first_failure, is_perspective


def _clipping_problem(clipping_range, projection) -> str | None:
    near, far = float(clipping_range[0]), float(clipping_range[1])
    if not is_finite(clipping_range):
        return "has a NaN or infinite component"
    if near < 0:
        return f"has a negative near plane {near:g}"
    if far <= near:
        return f"has far {far:g} <= near {near:g}"
    if near == 0 and is_perspective(projection):
        return "has near 0 on a perspective camera"
    return None


class ClippingRangeInvalid(Rule):
    """The render camera's clippingRange is non-finite, negative, inverted or zero-near.

    ## What it does
    On each effective render camera (since catalog Revision 2 also that of a
    product rendered on its own, R2-4), read at the rendered times of
    `clippingRange` and `projection` (R2-1: the default time when neither has
    time samples, else their sample times inside the stage's authored
    `startTimeCode`..`endTimeCode` plus both ends, or all of them without a
    range; capped), reports a
    `clippingRange` (near, far) with a NaN or infinite component, `near < 0`,
    `far <= near`, or `near == 0` while the camera is perspective.

    ## Why is this bad?
    *"The camera clippingRange attribute sets the near and far ranges of the
    camera frustrum. Anything falling outside the clipping range is omitted."*
    (`docs/user_guides/render_user_guide.rst`). An inverted or zero-near range
    gives an empty or degenerate perspective frustum: nothing, or only
    z-fighting, renders.

    Renderers read the camera at the frame being rendered, where an
    attribute's time samples beat its default value (catalog R2-1), so a
    default value no frame renders is not reported.

    ## Example
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Camera "cam"
        {
            float2 clippingRange = (10, 1)
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/cam>
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Camera "cam"
        {
            float2 clippingRange = (0.1, 10000)
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/cam>
        }
    }
    ```

    ## Fix safety
    No automatic fix: the intended near and far distances are unknown.
    """

    code = "CA009"
    name = "clipping-range-invalid"
    severity = Severity.ERROR
    partial_composition = True

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for use in effective_cameras(ctx):
            failure = first_failure(
                use.prim,
                ("clippingRange", "projection"),
                _clipping_problem,
                ctx,
            )
            if failure is not None:
                time, problem = failure
                yield Diagnostic(
                    message=f"render camera clippingRange {problem} ({at_time(time)}); author "
                    "finite "
                    "(near, far) with 0 <= near < far (near > 0 when perspective), "
                    "e.g. (0.1, 100000)",
                    at=use.prim.GetAttribute("clippingRange"),
                )
