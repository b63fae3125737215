"""CA007 depth-of-field-disabled-with-fstop."""

from __future__ import annotations

from collections.abc import Iterator

from usdrender_lint.api import Context, Diagnostic, Rule, Severity
from usdrender_lint.api.resolve import authored_rendered_times, prim_values

from .._camera import at_time, positive_finite


class DepthOfFieldDisabledWithFStop(Rule):
    """disableDepthOfField discards the render camera's authored fStop.

    ## What it does
    For each render configuration with a valid camera (since catalog Revision 2
    also a product rendered on its own, R2-4), reports an effective
    `disableDepthOfField = true` when the camera authors an `fStop > 0` at a
    rendered time (R2-1: the default time when `fStop` has no time samples,
    else its sample times inside the stage's authored
    `startTimeCode`..`endTimeCode` plus both ends, or all of them without a
    range; capped). An `fStop` left at its
    fallback `0` already means no depth of field, so it is not reported.

    ## Why is this bad?
    *"Use to disable all depth of field by setting F-stop of the targeted
    camera to infinity."* (`RenderSettings.md`); the camera's *"fStop ...
    Defaults to 0.0, which turns off depth of field effects."*
    (`usdGeom/schema.usda`). Legitimate for previews, but on a final-quality
    settings it silently removes the camera department's creative choice.

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
            float fStop = 2.8
            float focusDistance = 350
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/cam>
            uniform bool disableDepthOfField = 1
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
            float fStop = 2.8
            float focusDistance = 350
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
    No automatic fix: disabling depth of field may be intended (previews).
    """

    code = "CA007"
    name = "depth-of-field-disabled-with-fstop"
    severity = Severity.INFO
    partial_composition = True

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for config in ctx.configurations:
            camera = config.camera_prim
            # Whether any spec names the camera's fStop first (its authored names,
            # listed once per camera; most author none), where the effective
            # disableDepthOfField is a record per configuration. Its value is
            # read only when depth of field is disabled, as before.
            if camera is None or not prim_values(camera).may_be_authored("fStop"):
                continue
            disable = config.effective("disableDepthOfField")
            if not disable.value or not prim_values(camera).has_value("fStop"):
                continue
            fstop = prim_values(camera).attribute("fStop")
            for time in authored_rendered_times((fstop,), ctx.time_sample_cap):
                value = fstop.Get(time)
                if positive_finite(value):
                    yield Diagnostic(
                        message=f"{config.describe()}: disableDepthOfField = true discards the "
                        f"camera <{camera.GetPath()}> fStop {value:g} ({at_time(time)}); "
                        "remove disableDepthOfField if this is a final render",
                        at=disable.attr,
                    )
                    break
