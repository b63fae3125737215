"""CA: the render camera of each render configuration."""

from __future__ import annotations

from collections.abc import Iterator
from functools import partial

from pxr import Sdf, Usd, UsdGeom, UsdRender

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity
from usdrender_lint.resolve import (
    RenderConfiguration,
    allowed_tokens,
    describe_prim_type,
    evaluation_times,
    forwarded_targets,
    has_authored_value,
    is_finite,
    is_usable,
)

from ._camera import (
    at_time,
    config_owners,
    effective_cameras,
    first_failure,
    is_perspective,
    positive_finite,
    usable_cameras,
)


def _camera_rel_label(config: RenderConfiguration) -> str:
    return str(config.camera_relationship.GetPath())


def _set_settings_camera(settings_path: Sdf.Path, camera_path: Sdf.Path):
    def apply(stage: Usd.Stage) -> None:
        settings = UsdRender.SettingsBase(stage.GetPrimAtPath(settings_path))
        settings.CreateCameraRel().SetTargets([camera_path])

    return apply


class CameraUnset(Rule):
    """A render configuration has no camera at all.

    ## What it does
    For each render configuration (a RenderSettings with each usable product
    of its `products`, or the settings alone when it has none), reports when
    the effective camera is empty: the product's `camera` has no forwarded
    target and neither has the settings' `camera`. An authored empty product
    relationship (`rel camera = []`) does not clear the settings camera, so it
    is not a finding when the settings has one.

    ## Why is this bad?
    *"This relationship specifies the primary camera to use for a render. The
    relationship must target a Camera."* (`RenderSettings.md`). With no camera
    `UsdRenderComputeSpec` posts *"Could not find camera <> for the render
    product"* and drops the product from the render
    (`pxr/usd/usdRender/spec.cpp`).

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel products = </Render/Beauty>
        }

        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
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
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/cam>
            rel products = </Render/Beauty>
        }

        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
        }
    }
    ```

    ## Fix safety
    Unsafe: when the stage holds exactly one usable Camera, the fix targets it
    from the RenderSettings' `camera`. It picks a camera for you, so review it.
    """

    code = "CA001"
    name = "camera-unset"
    severity = Severity.ERROR
    fix_safety = "unsafe"

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for config in ctx.configurations:
            if config.camera_target is not None:
                continue
            settings_path = config.settings.GetPath()
            if config.product is None:
                what = f"RenderSettings <{settings_path}> has no camera"
                effect = "renderers have no view to render"
            else:
                what = (
                    f"RenderProduct <{config.product.GetPath()}> of <{settings_path}> has no "
                    "camera (neither the product's nor the settings' camera has a target)"
                )
                effect = 'UsdRenderComputeSpec drops the product ("Could not find camera")'
            fix = None
            cameras = usable_cameras(ctx)
            if len(cameras) == 1:
                camera_path = cameras[0].GetPath()
                fix = Fix(
                    f"target the stage's only Camera <{camera_path}> from <{settings_path}>",
                    False,
                    _set_settings_camera(settings_path, camera_path),
                )
            yield Diagnostic(
                f"{what}; {effect}. Author rel camera = </path/to/Camera> on "
                f"<{settings_path}> (or on the product)",
                at=config.settings,
                fix=fix,
            )


class CameraMultipleTargets(Rule):
    """A camera relationship of a render configuration has several targets.

    ## What it does
    Reports the `camera` relationship of a RenderSettings, or of a RenderProduct
    in its `products`, when it has more than one forwarded target.

    ## Why is this bad?
    The relationship names *"the primary camera"*, singular
    (`RenderSettings.md`). `UsdRenderComputeSpec` keeps only the first target
    (`pd->cameraPath = targets[0]`, `pxr/usd/usdRender/spec.cpp`), so the others
    are silently ignored and which one wins depends on list-op composition
    order. Stereo renders use one product per eye.

    ## Example
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Camera "cam_left"
        {
        }

        def Camera "cam_right"
        {
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = [</World/cam_left>, </World/cam_right>]
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Camera "cam_left"
        {
        }

        def Camera "cam_right"
        {
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/cam_left>
            rel products = [</Render/Left>, </Render/Right>]
        }

        def RenderProduct "Left"
        {
            token productName = "left.exr"
        }

        def RenderProduct "Right"
        {
            rel camera = </World/cam_right>
            token productName = "right.exr"
        }
    }
    ```

    ## Fix safety
    No automatic fix: only the author knows which camera is meant.
    """

    code = "CA002"
    name = "camera-multiple-targets"
    severity = Severity.WARNING

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        seen: set[Sdf.Path] = set()
        for config in ctx.configurations:
            for owner in config_owners(config):
                rel = owner.GetRelationship("camera")
                targets = forwarded_targets(rel)
                if len(targets) < 2 or rel.GetPath() in seen:
                    continue
                seen.add(rel.GetPath())
                listed = ", ".join(f"<{t}>" for t in targets)
                yield Diagnostic(
                    f"camera has {len(targets)} targets ({listed}); renderers use only the "
                    f"first, <{targets[0]}>, and ignore the rest. Keep one camera here "
                    "(use one RenderProduct per camera for stereo)",
                    at=rel,
                )


class CameraTargetMissing(Rule):
    """The render camera target does not exist, or is a Camera that is not usable.

    ## What it does
    For each render configuration (a RenderSettings with each of its products),
    takes the effective camera (the product's first forwarded `camera` target
    if it has one, else the settings') and reports it when no prim exists at
    that path on the composed stage, or when the prim is a Camera that is
    inactive, only an `over`, or abstract (a `class`). Relative targets are
    anchored by Sdf to the owning prim before the check.

    ## Why is this bad?
    *"This relationship specifies the primary camera to use for a render. The
    relationship must target a Camera."* (`RenderSettings.md`).
    `UsdRenderComputeSpec` drops the product with *"Could not find camera"*
    (`pxr/usd/usdRender/spec.cpp`), and Hydra's default traversal never sees
    an inactive, `over`-only or abstract camera.

    ## Example
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Camera "shotCam"
        {
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/main_cam>
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Camera "shotCam"
        {
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/shotCam>
        }
    }
    ```

    ## Fix safety
    No automatic fix: only the author knows which camera was meant.
    """

    code = "CA003"
    name = "camera-target-missing"
    severity = Severity.ERROR

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for config in ctx.configurations:
            target = config.camera_target
            if target is None:
                continue
            if target.is_missing:
                reason = target.problem
            elif target.prim is not None and target.prim.IsA(UsdGeom.Camera) and not target.ok:
                reason = f"is a Camera but {target.problem}"
            else:
                continue
            yield Diagnostic(
                f"camera target <{target.path}> {reason}; point "
                f"{_camera_rel_label(config)} at a defined, active Camera prim",
                at=config.camera_relationship,
            )


def _single_camera_descendant(prim: Usd.Prim) -> Usd.Prim | None:
    cameras = [
        p for p in Usd.PrimRange(prim) if p != prim and p.IsA(UsdGeom.Camera) and is_usable(p)
    ]
    return cameras[0] if len(cameras) == 1 else None


def _retarget(rel_path: Sdf.Path, new_target: Sdf.Path):
    def apply(stage: Usd.Stage) -> None:
        rel = stage.GetRelationshipAtPath(rel_path)
        targets = list(rel.GetTargets())
        rel.SetTargets([new_target, *targets[1:]])

    return apply


class CameraTargetNotCamera(Rule):
    """The render camera target is not a Camera prim.

    ## What it does
    For each render configuration, reports the effective camera target when it
    resolves to a prim that is not a `UsdGeom.Camera` (an Xform camera rig, a
    Scope, a typeless `def`) or to a property path such as
    `</World/cam.focalLength>`.

    ## Why is this bad?
    *"This relationship specifies the primary camera to use for a render. The
    relationship must target a Camera."* (`RenderSettings.md`); *"It must
    target a UsdGeomCamera."* (`pxr/usd/usdRender/schema.usda`). spec.cpp reads
    the target as `UsdGeomCamera`, and anything else drops the product with
    *"Could not find camera"*.

    ## Example
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Xform "camRig"
        {
            def Camera "cam"
            {
            }
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/camRig>
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Xform "camRig"
        {
            def Camera "cam"
            {
            }
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/camRig/cam>
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when the target prim has exactly one Camera descendant
    (the rig case) the fix retargets to it; a property path is retargeted to its
    owning prim when that prim is a Camera. Otherwise there is no fix.
    """

    code = "CA004"
    name = "camera-target-not-camera"
    severity = Severity.ERROR
    fix_safety = "safe-conditional"

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for config in ctx.configurations:
            target = config.camera_target
            if target is None or target.is_missing:
                continue
            rel = config.camera_relationship
            suggestion: Usd.Prim | None = None
            if target.path.IsPropertyPath():
                what = "a property, not a prim"
                owner = ctx.stage.GetPrimAtPath(target.path.GetPrimPath())
                if owner and owner.IsA(UsdGeom.Camera) and is_usable(owner):
                    suggestion = owner
            elif not target.prim.IsA(UsdGeom.Camera):
                what = describe_prim_type(target.prim)
                if target.problem:
                    what += f" that {target.problem}"
                suggestion = _single_camera_descendant(target.prim)
            else:
                continue
            if suggestion is None:
                yield Diagnostic(
                    f"camera target <{target.path}> is {what}, not a Camera; "
                    "point it at a Camera prim",
                    at=rel,
                )
                continue
            new_path = suggestion.GetPath()
            yield Diagnostic(
                f"camera target <{target.path}> is {what}, not a Camera; "
                f"target the Camera <{new_path}> instead",
                at=rel,
                fix=Fix(
                    f"retarget camera to <{new_path}>", True, _retarget(rel.GetPath(), new_path)
                ),
            )


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
    On each effective render camera, evaluated at the default time and at every
    authored time sample (capped): reports `horizontalAperture` or
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
                        f"render camera {names[0]} {problem} ({at_time(time)})",
                        at=camera.GetAttribute(names[0]),
                    )


def _author_conform_policy(settings_path: Sdf.Path):
    def apply(stage: Usd.Stage) -> None:
        settings = UsdRender.SettingsBase(stage.GetPrimAtPath(settings_path))
        settings.CreateAspectRatioConformPolicyAttr().Set(UsdRender.Tokens.expandAperture)

    return apply


def _aspect_mismatch(
    horizontal, vertical, image: tuple[float, str], tolerance: float
) -> str | None:
    if not (positive_finite(horizontal) and positive_finite(vertical)):
        return None  # CA005 reports it
    image_aspect, image_how = image
    aperture_aspect = horizontal / vertical
    if abs(image_aspect - aperture_aspect) / aperture_aspect <= tolerance:
        return None
    return (
        f"image aspect {image_aspect:.4g} ({image_how}) differs from the camera "
        f"aperture aspect {aperture_aspect:.4g} ({horizontal:g} / {vertical:g})"
    )


def _image_aspect(config: RenderConfiguration) -> tuple[float, str] | None:
    """The configuration's image aspect (width / height * pixelAspectRatio,
    fallbacks included) and how it was computed; None when an input is invalid
    (SE001 and SE002 report those)."""
    resolution = config.effective("resolution").value
    pixel_aspect = config.effective("pixelAspectRatio").value
    width, height = int(resolution[0]), int(resolution[1])
    if width <= 0 or height <= 0 or not positive_finite(pixel_aspect):
        return None
    how = f"{width}x{height}"
    if pixel_aspect != 1:
        how += f", pixelAspectRatio {pixel_aspect:g}"
    return width / height * pixel_aspect, how


class AspectRatioMismatchImplicitConform(Rule):
    """Image and camera aspect ratios differ and no aspectRatioConformPolicy says how to resolve it.

    ## What it does
    For each render configuration with a valid camera, compares the image
    aspect (`resolution` width / height times `pixelAspectRatio`, the product's
    authored value else the settings', fallbacks included) with the camera's
    aperture aspect (`horizontalAperture / verticalAperture`, fallbacks
    included, at the default time and every authored time sample). It reports
    a relative difference above 1% when neither the settings nor the product
    authors `aspectRatioConformPolicy`, so the fallback `expandAperture`
    silently decides. Invalid inputs are skipped (SE001, SE002, CA005 report
    them). The schema fallbacks alone mismatch (2048x1080 is 1.896, the default
    aperture 1.370), which is intended.

    ## Why is this bad?
    *"Because the camera aperture and image dimensions are specified
    independently, mismatches between aspect ratios can occur. ... Use the
    aspectRatioConformPolicy attribute to communicate to the renderer how to
    resolve the mismatch."* (`RenderSettings.md`). The fallback
    `expandAperture` exposes scene content outside the approved framing
    (`pxr/usd/usdRender/schema.usda`, `_ApplyAspectRatioPolicy` in
    `pxr/usd/usdRender/spec.cpp`).

    ## Example
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Camera "cam"
        {
            float horizontalAperture = 20.955
            float verticalAperture = 15.2908
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/cam>
            uniform int2 resolution = (1920, 1080)
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
            float horizontalAperture = 20.955
            float verticalAperture = 15.2908
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/cam>
            uniform int2 resolution = (1920, 1080)
            uniform token aspectRatioConformPolicy = "cropAperture"
        }
    }
    ```

    ## Fix safety
    Safe: the fix authors `aspectRatioConformPolicy = "expandAperture"` on the
    RenderSettings, which makes today's implicit behaviour explicit. Choosing
    another policy is left to you.
    """

    code = "CA006"
    name = "aspect-ratio-mismatch-implicit-conform"
    severity = Severity.WARNING
    fix_safety = "safe"

    #: Relative aspect difference tolerated (catalog: 1%).
    tolerance = 0.01

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for config in ctx.configurations:
            camera = config.camera
            if camera is None or self._has_explicit_policy(config):
                continue
            image = _image_aspect(config)
            if image is None:
                continue
            failure = first_failure(
                camera.GetPrim(),
                ("horizontalAperture", "verticalAperture"),
                partial(_aspect_mismatch, image=image, tolerance=self.tolerance),
                ctx,
            )
            if failure is None:
                continue
            time, problem = failure
            settings_path = config.settings.GetPath()
            yield Diagnostic(
                f"{config.describe()}: {problem} ({at_time(time)}) and no "
                "aspectRatioConformPolicy is authored, so the fallback expandAperture "
                "silently renders scene content outside the camera framing; author "
                f"aspectRatioConformPolicy on <{settings_path}> or match the aspects",
                at=config.settings,
                fix=Fix(
                    'author aspectRatioConformPolicy = "expandAperture" (today\'s behaviour)',
                    True,
                    _author_conform_policy(settings_path),
                ),
            )

    @staticmethod
    def _has_explicit_policy(config: RenderConfiguration) -> bool:
        return any(
            has_authored_value(p.GetAttribute("aspectRatioConformPolicy"))
            for p in config_owners(config)
        )


class DepthOfFieldDisabledWithFStop(Rule):
    """disableDepthOfField discards the render camera's authored fStop.

    ## What it does
    For each render configuration with a valid camera, reports an effective
    `disableDepthOfField = true` when the camera authors an `fStop > 0` at the
    default time or at any time sample (capped). An `fStop` left at its
    fallback `0` already means no depth of field, so it is not reported.

    ## Why is this bad?
    *"Use to disable all depth of field by setting F-stop of the targeted
    camera to infinity."* (`RenderSettings.md`); the camera's *"fStop ...
    Defaults to 0.0, which turns off depth of field effects."*
    (`usdGeom/schema.usda`). Legitimate for previews, but on a final-quality
    settings it silently removes the camera department's creative choice.

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

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for config in ctx.configurations:
            camera = config.camera
            disable = config.effective("disableDepthOfField")
            if camera is None or not disable.value:
                continue
            fstop = camera.GetFStopAttr()
            if not has_authored_value(fstop):
                continue
            for time in evaluation_times(fstop, ctx.time_sample_cap):
                value = fstop.Get(time)
                if positive_finite(value):
                    yield Diagnostic(
                        f"{config.describe()}: disableDepthOfField = true discards the "
                        f"camera <{camera.GetPath()}> fStop {value:g} ({at_time(time)}); "
                        "remove disableDepthOfField if this is a final render",
                        at=disable.attr,
                    )
                    break


class ShutterIntervalInverted(Rule):
    """The render camera's shutter:open is after its shutter:close.

    ## What it does
    For each effective render camera used by a configuration with motion blur
    enabled (effective `disableMotionBlur` false), reports `shutter:open >
    shutter:close` at the default time or at any time sample (capped) of either
    attribute, at the first failing time. Both fall back to 0.

    ## Why is this bad?
    *"shutter:close ... A value greater or equal to shutter:open should be
    authored, otherwise there is no exposure and a renderer should produce a
    black image."* (`usdGeom/schema.usda`, usd-core 26.11). With motion blur
    disabled the interval is forced to [0, 0], so that case is skipped.

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
                    f"render camera {problem} ({at_time(time)}): there is no exposure and "
                    "renderers produce a black image; author shutter:close >= shutter:open "
                    "(e.g. open -0.25, close 0.25)",
                    at=use.prim,
                )


def _inverted_shutter(shutter_open, shutter_close) -> str | None:
    if shutter_open > shutter_close:
        return f"shutter:open {shutter_open:g} is after shutter:close {shutter_close:g}"
    return None


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
    On each effective render camera, evaluated at the default time and at every
    authored time sample (capped) of `clippingRange` or `projection`, reports a
    `clippingRange` (near, far) with a NaN or infinite component, `near < 0`,
    `far <= near`, or `near == 0` while the camera is perspective.

    ## Why is this bad?
    *"The camera clippingRange attribute sets the near and far ranges of the
    camera frustrum. Anything falling outside the clipping range is omitted."*
    (`docs/user_guides/render_user_guide.rst`). An inverted or zero-near range
    gives an empty or degenerate perspective frustum: nothing, or only
    z-fighting, renders.

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
                    f"render camera clippingRange {problem} ({at_time(time)}); author finite "
                    "(near, far) with 0 <= near < far (near > 0 when perspective), "
                    "e.g. (0.1, 100000)",
                    at=use.prim.GetAttribute("clippingRange"),
                )


RULES = (
    CameraUnset,
    CameraMultipleTargets,
    CameraTargetMissing,
    CameraTargetNotCamera,
    CameraOpticsInvalid,
    AspectRatioMismatchImplicitConform,
    DepthOfFieldDisabledWithFStop,
    ShutterIntervalInverted,
    ClippingRangeInvalid,
)
