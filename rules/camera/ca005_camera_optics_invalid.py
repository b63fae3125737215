"""CA005 camera-optics-invalid."""

from __future__ import annotations

from collections.abc import Iterator
from functools import partial

from usdrender_lint.api import Context, Diagnostic, Rule, Severity
from usdrender_lint.api.resolve import allowed_tokens

from .._camera import at_time, effective_cameras, first_failure, is_perspective, positive_finite


def _aperture_problem(value) -> str | None:
    if positive_finite(value):
        return None
    return f"is {value:g}; it must be finite and > 0 (tenths of a scene unit, e.g. 20.955)"


def _projection_problem(projection, allowed: tuple[str, ...]) -> str | None:
    if str(projection) in allowed:
        return None
    return f"is {str(projection)!r}; use one of {', '.join(allowed)}"


def _focal_length_problem(focal_length, projection) -> str | None:
    if not is_perspective(projection) or positive_finite(focal_length):
        return None
    return (
        f"is {focal_length:g} on a perspective camera; it must be finite and > 0 "
        "(tenths of a scene unit, e.g. 50)"
    )


class CameraOpticsInvalid(Rule):
    """The render camera has a non-positive aperture or focal length, or an unknown projection.

    ## What it does
    On each effective render camera (since catalog Revision 2 also that of a
    product rendered on its own, R2-4), read at the rendered times (R2-1: the
    default time when the attribute has no time samples, else its sample times
    inside the stage's authored `startTimeCode`..`endTimeCode` plus both ends,
    or all of them without a range; capped), reports `horizontalAperture` or
    `verticalAperture` that is `<= 0` or not finite, a `projection` outside its
    allowedTokens (`perspective`, `orthographic`), and, while the camera is
    perspective, a `focalLength` that is `<= 0` or not finite. Each attribute is
    reported once, at its first failing time. Unauthored attributes use their
    schema fallbacks, which are valid.

    ## Why is this bad?
    The aperture *"bounds the X and Y axes of screen space. The projection of
    the aperture bounds to screen coordinates is known as the screen window."*
    (`docs/user_guides/render_user_guide.rst`, *Defining the Render Camera*).
    A zero aperture or focal length gives a degenerate frustum, and
    `UsdRenderComputeSpec` skips aspect-ratio conforming when an aperture size
    is `<= 0` (`pxr/usd/usdRender/spec.cpp`).

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
            float horizontalAperture = 36
            float verticalAperture = 0
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
            float horizontalAperture = 36
            float verticalAperture = 20.25
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
    No automatic fix: the intended optics are unknown.
    """

    code = "CA005"
    name = "camera-optics-invalid"
    severity = Severity.ERROR
    partial_composition = True

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for use in effective_cameras(ctx):
            camera = use.prim
            projections = allowed_tokens(camera, "projection")
            checks = (
                (("horizontalAperture",), _aperture_problem),
                (("verticalAperture",), _aperture_problem),
                (("projection",), partial(_projection_problem, allowed=projections)),
                (("focalLength", "projection"), _focal_length_problem),
            )
            for names, check in checks:
                failure = first_failure(camera, names, check, ctx)
                if failure is not None:
                    time, problem = failure
                    yield Diagnostic(
                        message=f"render camera {names[0]} {problem} ({at_time(time)})",
                        at=camera.GetAttribute(names[0]),
                    )
