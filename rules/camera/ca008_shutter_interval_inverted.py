"""CA008 shutter-interval-inverted."""

from __future__ import annotations

from collections.abc import Iterator

from usdrender_lint.api import Context, Diagnostic, Rule, Severity

from .._camera import at_time, effective_cameras, first_failure


class ShutterIntervalInverted(Rule):
    """The render camera's shutter:open is after its shutter:close.

    ## What it does
    For each effective render camera used by a configuration with motion blur
    enabled (effective `disableMotionBlur` false; since catalog Revision 2 also
    a product rendered on its own, R2-4), reports `shutter:open >
    shutter:close` at the first failing rendered time (R2-1: the default time
    when neither has time samples, else their sample times inside the stage's
    authored `startTimeCode`..`endTimeCode` plus both ends, or all of them
    without a range; capped). Both fall back to 0.

    ## Why is this bad?
    *"shutter:close ... A value greater or equal to shutter:open should be
    authored, otherwise there is no exposure and a renderer should produce a
    black image."* (`usdGeom/schema.usda`, usd-core 26.11). With motion blur
    disabled the interval is forced to [0, 0], so that case is skipped.

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
            double shutter:close = -0.25
            double shutter:open = 0.25
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
            double shutter:close = 0.25
            double shutter:open = -0.25
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
    No automatic fix: swapping the values is plausible but could hide an
    animation error.
    """

    code = "CA008"
    name = "shutter-interval-inverted"
    severity = Severity.ERROR
    partial_composition = True

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for use in effective_cameras(ctx):
            if all(c.effective("disableMotionBlur").value for c in use.configurations):
                continue
            failure = first_failure(
                use.prim,
                ("shutter:open", "shutter:close"),
                _inverted_shutter,
                ctx,
            )
            if failure is not None:
                time, problem = failure
                yield Diagnostic(
                    message=f"render camera {problem} ({at_time(time)}): there is no exposure and "
                    "renderers produce a black image; author shutter:close >= shutter:open "
                    "(e.g. open -0.25, close 0.25)",
                    at=use.prim,
                )


def _inverted_shutter(shutter_open, shutter_close) -> str | None:
    if shutter_open > shutter_close:
        return f"shutter:open {shutter_open:g} is after shutter:close {shutter_close:g}"
    return None
