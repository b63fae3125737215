"""CA006 aspect-ratio-mismatch-implicit-conform."""

from __future__ import annotations

from collections.abc import Iterator
from functools import partial

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity
from usdrender_lint.api.resolve import RenderConfiguration

from .._camera import at_time, config_authors, first_failure, positive_finite


def _author_conform_policy(owner_path: Sdf.Path):
    def apply(stage: Usd.Stage) -> None:
        from pxr import UsdRender  # the schema API, imported only when a fix runs (start-up)

        owner = UsdRender.SettingsBase(stage.GetPrimAtPath(owner_path))
        owner.CreateAspectRatioConformPolicyAttr().Set(UsdRender.Tokens.expandAperture)

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
    authored value else the settings', fallbacks included; uniform, so read at
    the default time) with the camera's aperture aspect (`horizontalAperture /
    verticalAperture`, fallbacks included) at the rendered times (catalog R2-1:
    the default time when neither aperture has time samples, else their sample
    times inside the stage's authored `startTimeCode`..`endTimeCode` plus both
    ends, or all of them without a range; capped). It reports a relative
    difference above 1% when neither the settings nor the product authors
    `aspectRatioConformPolicy`, so the fallback `expandAperture` silently
    decides, naming the first failing time. A product rendered on its own (no
    usable RenderSettings targets it and it authors its own camera, R2-4) is a
    configuration of its own, with its own values and the fallbacks; its
    finding and fix go to the product. Invalid inputs are skipped (SE001, SE002, CA005 report
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

    ## Profiles
    Every profile keeps this rule. Under `omniverse` it was checked and kept:
    Omniverse's camera documentation lists the camera attributes RTX ignores
    (aperture offsets, shutter, stereo role), and the horizontal and vertical
    apertures are not among them, so RTX frames with both; no public NVIDIA
    source (Kit, RTX, ovrtx or Isaac Sim documentation) says how RTX resolves
    an aperture/image aspect mismatch or whether it reads
    `aspectRatioConformPolicy`, so the mismatch stays a risk on Kit viewport
    and ovrtx products.
    """

    code = "CA006"
    name = "aspect-ratio-mismatch-implicit-conform"
    severity = Severity.WARNING
    partial_composition = True
    fix_safety = "safe"

    #: Relative aspect difference tolerated (catalog: 1%).
    tolerance = 0.01

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for config in ctx.configurations:
            camera = config.camera_prim
            if camera is None or self._has_explicit_policy(config):
                continue
            image = _image_aspect(config)
            if image is None:
                continue
            failure = first_failure(
                camera,
                ("horizontalAperture", "verticalAperture"),
                partial(_aspect_mismatch, image=image, tolerance=self.tolerance),
                ctx,
            )
            if failure is None:
                continue
            time, problem = failure
            owner_path = config.owner.GetPath()
            yield Diagnostic(
                message=f"{config.describe()}: {problem} ({at_time(time)}) and no "
                "aspectRatioConformPolicy is authored, so the fallback expandAperture "
                "silently renders scene content outside the camera framing; author "
                f"aspectRatioConformPolicy on <{owner_path}> or match the aspects",
                at=config.owner,
                fix=Fix(
                    description='author aspectRatioConformPolicy = "expandAperture" (today\'s '
                    "behaviour)",
                    safe=True,
                    apply=_author_conform_policy(owner_path),
                ),
            )

    @staticmethod
    def _has_explicit_policy(config: RenderConfiguration) -> bool:
        return config_authors(config, "aspectRatioConformPolicy")
