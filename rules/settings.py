"""SE: RenderSettingsBase and RenderSettings attributes."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

from pxr import Sdf, Usd, UsdGeom, UsdRender, Vt

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity
from usdrender_lint.resolve import (
    DEFAULT_TIME,
    EffectiveValue,
    allowed_tokens,
    authored_value,
    composed_value,
    forwarded_targets,
    has_authored_value,
    is_finite,
    items,
    mismatched_spec,
    mismatched_specs,
    resolve_targets,
    time_samples,
    typed_target_problem,
)

from . import _colorspace
from ._corrections import set_value
from ._raster import pixel_centres, pixel_span

Apply = Callable[[Usd.Stage], None]


def _fmt(value: Any) -> str:
    """A value as it reads in a message: vectors as tuples, floats trimmed."""
    if value is None:
        return "no value"
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, float):
        return f"{value:g}"
    try:
        items = list(value)
    except TypeError:
        return str(value)
    if value and all(isinstance(v, str) for v in items):
        return "[" + ", ".join(f'"{v}"' for v in items) + "]"
    if not items and isinstance(value, Vt.TokenArray):
        return "[]"
    return "(" + ", ".join(_fmt(v) for v in items) + ")"


# -- data window (SE003, SE004, SE005) ------------------------------------------


def _data_window_problem(window, resolution) -> str | None:
    """Why an authored dataWindowNDC renders nothing sensible, or None."""
    components = items(window)
    xmin, ymin, xmax, ymax = (float(c) for c in components)
    if not is_finite(components):
        return "has a NaN or infinite component"
    if xmin >= xmax or ymin >= ymax:
        axis = "x" if xmin >= xmax else "y"
        return f"is inverted or empty on {axis} (min must be < max)"
    width, height = int(resolution[0]), int(resolution[1])
    if (
        width > 0
        and height > 0
        and (pixel_centres(xmin, xmax, width) == 0 or pixel_centres(ymin, ymax, height) == 0)
    ):
        return f"contains no pixel centre at resolution {width}x{height}"
    return None


@dataclass(frozen=True)
class _WindowUse:
    """An authored dataWindowNDC and a resolution it is rendered at."""

    window: EffectiveValue
    resolution: Any

    @property
    def values(self) -> tuple[float, float, float, float]:
        xmin, ymin, xmax, ymax = (float(c) for c in items(self.window.value))
        return xmin, ymin, xmax, ymax

    @property
    def text(self) -> str:
        return _fmt(tuple(round(c, 6) for c in self.values))


def _window_uses(ctx: Context) -> list[_WindowUse]:
    """Every authored dataWindowNDC with the resolution of each configuration
    it is used in: a product's window or resolution overrides the settings'
    (catalog SE003: checked once per settings that targets the product)."""

    def compute() -> list[_WindowUse]:
        uses = []
        for config in ctx.configurations:
            window = config.effective("dataWindowNDC")
            if window.authored:  # the resolution is read only for a window to check
                uses.append(_WindowUse(window, config.effective("resolution").value))
        for prim in [*ctx.prims_of(UsdRender.Settings), *ctx.untargeted_products]:
            attr = prim.GetAttribute("dataWindowNDC")
            if has_authored_value(attr):
                window = EffectiveValue(attr.Get(), attr, True)
                uses.append(_WindowUse(window, composed_value(prim, "resolution")))
        return uses

    return ctx.memo("settings.window_uses", compute)


def _well_formed_window_uses(ctx: Context) -> Iterator[_WindowUse]:
    """The uses SE003 accepts: SE004 and SE005 only look at those."""
    for use in _window_uses(ctx):
        if _data_window_problem(use.window.value, use.resolution) is None:
            yield use


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
    settings'). It is malformed when a component is NaN or infinite, when
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
    fix_safety = "unsafe"

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for use in _window_uses(ctx):
            window = use.window
            problem = _data_window_problem(window.value, use.resolution)
            if problem is None:
                continue
            xmin, _, xmax, _ = window.value
            fix = None
            if "inverted" in problem and is_finite(window.value) and xmin > xmax:
                fix = Fix("swap xmin and xmax", False, _swap_x(window.attr.GetPath()))
            yield Diagnostic(
                f"dataWindowNDC {use.text} {problem}; "
                "use (xmin, ymin, xmax, ymax) with min < max, e.g. (0, 0, 1, 1)",
                at=window.attr,
                fix=fix,
            )


class DataWindowOutsideAperture(Rule):
    """A well-formed dataWindowNDC lies entirely outside the camera aperture.

    ## What it does
    Reports an authored `dataWindowNDC` on a RenderSettings or RenderProduct
    that SE003 accepts but that does not overlap the unit square:
    `xmax <= 0`, `xmin >= 1`, `ymax <= 0` or `ymin >= 1`.

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

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for use in _well_formed_window_uses(ctx):
            xmin, ymin, xmax, ymax = use.values
            if xmax <= 0 or xmin >= 1 or ymax <= 0 or ymin >= 1:
                yield Diagnostic(
                    f"dataWindowNDC {use.text} does not overlap the camera aperture "
                    "(0, 0, 1, 1), so the image holds only overscan; NDC runs 0..1 across the "
                    "aperture: rescale pixel or percentage values, e.g. (0, 0, 1, 1)",
                    at=use.window.attr,
                )


class DataWindowCropOrOverscan(Rule):
    """A dataWindowNDC crops the aperture or renders overscan.

    ## What it does
    Reports an authored, well-formed `dataWindowNDC` that overlaps the unit
    square but differs from `(0, 0, 1, 1)`: *cropped* when `xmin > 0`,
    `ymin > 0`, `xmax < 1` or `ymax < 1`; *overscan* when a bound lies outside
    the unit square (both may apply). The message gives the pixel data window
    at the configuration's resolution.

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
                f"dataWindowNDC {use.text} {' and '.join(kinds)} the image{pixels}; "
                "if unintended, remove the opinion or author (0, 0, 1, 1)",
                at=use.window.attr,
            )


# -- scalar settings (SE001, SE002, SE006) ---------------------------------------


class ResolutionNonPositive(Rule):
    """resolution has a zero or negative component.

    ## What it does
    Checks `resolution` (`int2`, fallback `(2048, 1080)`): on a RenderSettings
    the composed value (authored or fallback), on a RenderProduct only an
    authored value, since only authored product values override the settings.
    It fires when a component is `<= 0`. With the option `require-authored`,
    a RenderSettings that leaves `resolution` at its fallback is reported too.

    ## Why is this bad?
    *"The image resolution in pixels. The render camera's screen window … is
    sampled by the renderer to a raster image of this resolution."*
    (`RenderSettings.md`). `UsdRenderComputeSpec` skips the aspect-ratio conform
    when `res[0] <= 0 || res[1] <= 0` (`pxr/usd/usdRender/spec.cpp`), and no
    image can have a non-positive size.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform int2 resolution = (1920, 0)
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
            uniform int2 resolution = (1920, 1080)
        }
    }
    ```

    ## Fix safety
    No automatic fix: the intended size cannot be guessed.

    ## Options
    `require-authored` (bool, default false): also report a RenderSettings
    whose `resolution` is unauthored. The fallback `(2048, 1080)` is a DCI-2K
    container, not HD, and rarely what a studio means (catalog, Ambiguous
    semantics 2).
    """

    @dataclass(frozen=True)
    class Options:
        require_authored: bool = False

    code = "SE001"
    name = "resolution-non-positive"
    severity = Severity.ERROR
    prim_types = (UsdRender.SettingsBase,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("resolution")
        is_settings = prim.IsA(UsdRender.Settings)
        value = composed_value(prim, "resolution") if is_settings else authored_value(attr)
        if value is None:
            return
        if min(items(value)) <= 0:
            yield Diagnostic(
                f"resolution {_fmt(value)} has a component <= 0; author a positive pixel size "
                "such as (1920, 1080)",
                at=attr,
            )
        elif is_settings and self.options.require_authored and not has_authored_value(attr):
            yield Diagnostic(
                f"resolution is not authored on {prim.GetPath()}, so renderers use the fallback "
                f"{_fmt(value)} (DCI-2K); author the intended size, e.g. "
                "uniform int2 resolution = (1920, 1080)",
                at=prim,
            )


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
    prim_types = (UsdRender.SettingsBase,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("pixelAspectRatio")
        ratio = authored_value(attr)
        if ratio is None or (math.isfinite(ratio) and ratio > 0):
            return
        yield Diagnostic(
            f"pixelAspectRatio is {_fmt(float(ratio))}; it must be a finite number > 0 "
            "(width/height of one pixel): author e.g. 1 for square pixels or 2 for a 2x "
            "anamorphic squeeze, or delete the opinion to get the fallback 1",
            at=attr,
        )


class AspectRatioConformPolicyInvalid(Rule):
    """An authored aspectRatioConformPolicy is not one of the schema's tokens.

    ## What it does
    Checks an authored `aspectRatioConformPolicy` on a RenderSettings or
    RenderProduct against the attribute's `allowedTokens`, read at run time
    from the prim definition (`expandAperture`, `cropAperture`,
    `adjustApertureWidth`, `adjustApertureHeight`, `adjustPixelAspectRatio` in
    usd-core 26.11). The comparison is case-sensitive.

    ## Why is this bad?
    `allowedTokens = ["expandAperture", "cropAperture", "adjustApertureWidth",
    "adjustApertureHeight", "adjustPixelAspectRatio"]`
    (`pxr/usd/usdRender/schema.usda`). `UsdRenderComputeSpec` matches these
    tokens exactly; any other value falls through every branch, so no conform
    is applied at all, not even the fallback `expandAperture`.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform token aspectRatioConformPolicy = "cropaperture"
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
            uniform token aspectRatioConformPolicy = "cropAperture"
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when the value matches exactly one allowed token
    ignoring case (`cropaperture`), the fix authors that token; otherwise no
    fix is offered.
    """

    code = "SE006"
    name = "aspect-ratio-conform-policy-invalid"
    severity = Severity.ERROR
    fix_safety = "safe-conditional"
    prim_types = (UsdRender.SettingsBase,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        name = "aspectRatioConformPolicy"
        attr = prim.GetAttribute(name)
        policy = authored_value(attr)
        allowed = allowed_tokens(prim, name)
        if policy is None or not allowed or policy in allowed:
            return
        same_letters = [t for t in allowed if t.lower() == str(policy).lower()]
        fix = None
        if len(same_letters) == 1:
            fix = Fix(
                f'set to "{same_letters[0]}"', True, set_value(attr.GetPath(), same_letters[0])
            )
        hint = f'did you mean "{same_letters[0]}"? ' if same_letters else ""
        yield Diagnostic(
            f'aspectRatioConformPolicy "{policy}" is not an allowed token, so no aspect-ratio '
            f"conform is applied at all; {hint}use one of {', '.join(allowed)} "
            "(case-sensitive)",
            at=attr,
            fix=fix,
        )


# -- motion blur (SE007, SE008) --------------------------------------------------


def _replace_instantaneous_shutter(prim_path: Sdf.Path, author_disable: bool) -> Apply:
    def apply(stage: Usd.Stage) -> None:
        prim = stage.GetPrimAtPath(prim_path)
        if author_disable:
            UsdRender.SettingsBase(prim).CreateDisableMotionBlurAttr().Set(True)
        prim.RemoveProperty("instantaneousShutter")
        attr = prim.GetAttribute("instantaneousShutter")
        if attr.HasAuthoredValue():
            # The opinion comes through an arc (an inherited class) or sits below
            # the edited layer: removing it there would touch other prims, so block it here.
            attr.Block()

    return apply


class InstantaneousShutterDeprecated(Rule):
    """instantaneousShutter is authored; it is deprecated and ignored.

    ## What it does
    Reports a RenderSettings or RenderProduct with an authored
    `instantaneousShutter` opinion, `true` or `false`.

    ## Why is this bad?
    *"Deprecated, use disableMotionBlur instead."* (`RenderSettings.md`,
    `pxr/usd/usdRender/schema.usda`). Since v22.05 `pxr/usd/usdRender/spec.cpp`
    never reads the attribute and UsdImaging skips it, so an authored `true`
    has no effect at all in OpenUSD's own consumers.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform bool instantaneousShutter = 1
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
            uniform bool disableMotionBlur = 1
        }
    }
    ```

    ## Fix safety
    Safe, conditional: `instantaneousShutter = true` becomes
    `disableMotionBlur = true` when `disableMotionBlur` has no authored opinion
    (otherwise see SE008); `false` is simply removed. The old attribute set
    `shutter:close = shutter:open` (one sample at frame + `shutter:open`), the
    new one samples at the frame: identical only when the camera's
    `shutter:open` is 0.
    """

    code = "SE007"
    name = "instantaneous-shutter-deprecated"
    severity = Severity.WARNING
    fix_safety = "safe-conditional"
    prim_types = (UsdRender.SettingsBase,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("instantaneousShutter")
        if not has_authored_value(attr):
            return
        value = bool(attr.Get())
        fix = None
        if not value:
            fix = Fix(
                "remove the deprecated instantaneousShutter opinion",
                True,
                _replace_instantaneous_shutter(prim.GetPath(), False),
            )
        elif not has_authored_value(prim.GetAttribute("disableMotionBlur")):
            fix = Fix(
                "replace with disableMotionBlur = true (same result only when the camera's "
                "shutter:open is 0)",
                True,
                _replace_instantaneous_shutter(prim.GetPath(), True),
            )
        advice = "author disableMotionBlur = true instead" if value else "remove it"
        yield Diagnostic(
            f"instantaneousShutter = {str(value).lower()} is deprecated and ignored by "
            f"OpenUSD's render consumers; {advice}",
            at=attr,
            fix=fix,
        )


class InstantaneousShutterConflict(Rule):
    """instantaneousShutter = true contradicts an authored disableMotionBlur = false.

    ## What it does
    Reports a RenderSettings or RenderProduct that authors both
    `instantaneousShutter = true` and `disableMotionBlur = false`. When
    `disableMotionBlur` is unauthored only SE007 fires.

    ## Why is this bad?
    The author asked for no motion blur and for motion blur at once. OpenUSD
    ignores the deprecated attribute (*"Deprecated, use disableMotionBlur
    instead."*, `RenderSettings.md`; never read by `pxr/usd/usdRender/spec.cpp`),
    so the render **has** motion blur, while legacy consumers that still honour
    `instantaneousShutter` render without it: the same file renders
    differently per renderer.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform bool disableMotionBlur = 0
            uniform bool instantaneousShutter = 1
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
            uniform bool disableMotionBlur = 1
        }
    }
    ```

    ## Fix safety
    No automatic fix: the intent is contradictory and a human decides.
    """

    code = "SE008"
    name = "instantaneous-shutter-conflict"
    severity = Severity.WARNING
    prim_types = (UsdRender.SettingsBase,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        shutter = prim.GetAttribute("instantaneousShutter")
        disable = prim.GetAttribute("disableMotionBlur")
        if authored_value(shutter) is True and authored_value(disable) is False:
            yield Diagnostic(
                "instantaneousShutter = true asks for no motion blur but disableMotionBlur = "
                "false asks for it; OpenUSD ignores instantaneousShutter, so this renders WITH "
                "motion blur: remove instantaneousShutter and set disableMotionBlur to the "
                "intended value",
                at=shutter,
            )


# -- purposes (SE009, SE010, SE011) ----------------------------------------------


def _duplicates(tokens: Sequence[str]) -> list[str]:
    seen: set[str] = set()
    repeated: list[str] = []
    for token in tokens:
        if token in seen and token not in repeated:
            repeated.append(token)
        seen.add(token)
    return repeated


def _quoted(tokens: Sequence[str]) -> str:
    return ", ".join(f'"{t}"' for t in tokens)


#: The purposes UsdGeom knows, in its order (fixed for the process).
_PURPOSES = tuple(str(t) for t in UsdGeom.Imageable.GetOrderedPurposeTokens())


class IncludedPurposesInvalid(Rule):
    """includedPurposes names a purpose that does not exist, or repeats one.

    ## What it does
    Checks an authored `includedPurposes` on a RenderSettings: every token must
    be an imageable purpose (`UsdGeom.Imageable.GetOrderedPurposeTokens()`:
    `default`, `render`, `proxy`, `guide` in usd-core 26.11), listed once.

    ## Why is this bad?
    *"Imageable purpose values (e.g. default, render, proxy, guide) that should
    be included in the render."* (RenderSettings prim definition, usd-core
    26.11); *"A prim can only have one purpose, and the purpose can be one of
    the following: default … render … proxy … guide"*
    (`docs/user_guides/render_user_guide.rst`). A token such as `preview` (a
    material-binding purpose) matches no prim.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform token[] includedPurposes = ["default", "render", "preview"]
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
            uniform token[] includedPurposes = ["default", "render"]
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when the only problem is repeated tokens, the fix drops
    the repeats and keeps the order. Unknown tokens are not fixed.
    """

    code = "SE009"
    name = "included-purposes-invalid"
    severity = Severity.WARNING
    fix_safety = "safe-conditional"
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("includedPurposes")
        purposes = authored_value(attr)
        if purposes is None:
            return
        tokens = items(purposes)
        known = _PURPOSES
        unknown = [t for t in dict.fromkeys(tokens) if t not in known]
        repeated = _duplicates(tokens)
        problems = []
        if unknown:
            verb = "is not a purpose" if len(unknown) == 1 else "are not purposes"
            problems.append(f"{_quoted(unknown)} {verb}")
        if repeated:
            problems.append(
                f"{_quoted(repeated)} {'is' if len(repeated) == 1 else 'are'} listed more than once"
            )
        if not problems:
            return
        fix = None
        if not unknown:
            unique = Vt.TokenArray(list(dict.fromkeys(tokens)))
            fix = Fix("drop the repeated purposes", True, set_value(attr.GetPath(), unique))
        yield Diagnostic(
            f"includedPurposes {_fmt(purposes)}: {'; '.join(problems)}; list each of "
            f"{', '.join(known)} at most once",
            at=attr,
            fix=fix,
        )


class IncludedPurposesMissingDefault(Rule):
    """An authored includedPurposes does not list "default".

    ## What it does
    Reports a RenderSettings whose authored `includedPurposes` lacks
    `"default"`, including an authored empty array. The fallback
    `["default", "render"]` never fires this rule.

    ## Why is this bad?
    The schema says *"Only imageable prims with purpose set to one of the
    includedPurposes values will be rendered"* (RenderSettings prim
    definition, usd-core 26.11) while the user docs say *"Renderers are
    expected to render default purpose prims for all render situations."*
    (`pxr/usd/usdRender/userDoc/overview.md`). Listing `default` is correct
    under both readings; omitting it makes the result renderer-dependent.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform token[] includedPurposes = ["render"]
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
            uniform token[] includedPurposes = ["default", "render"]
        }
    }
    ```

    ## Fix safety
    Safe: the fix prepends `"default"` to the authored array in the layer that
    authors it, which is right under both readings of the docs.
    """

    code = "SE010"
    name = "included-purposes-missing-default"
    severity = Severity.WARNING
    fix_safety = "safe"
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("includedPurposes")
        purposes = authored_value(attr)
        if purposes is None or UsdGeom.Tokens.default_ in purposes:
            return
        fixed = Vt.TokenArray([UsdGeom.Tokens.default_, *purposes])
        yield Diagnostic(
            f'includedPurposes {_fmt(purposes)} does not list "default"; whether prims '
            "without an authored purpose render then depends on the renderer: author "
            f"{_fmt(fixed)}",
            at=attr,
            fix=Fix('prepend "default"', True, set_value(attr.GetPath(), fixed)),
        )


#: Names people use for the all-purpose binding, whose token is the empty string.
_ALL_PURPOSE_ALIASES = ("allPurpose", "all", "default")


class MaterialBindingPurposesInvalid(Rule):
    """materialBindingPurposes names an unknown purpose, repeats one, or is empty.

    ## What it does
    Checks an authored `materialBindingPurposes` on a RenderSettings against
    the attribute's `allowedTokens` (`full`, `preview` and the empty token
    `""` in usd-core 26.11); repeated tokens and an authored empty array are
    reported too.

    ## Why is this bad?
    `allowedTokens = ["full", "preview", ""]` and *"The empty string indicates
    the "allPurpose" binding."* (`pxr/usd/usdRender/schema.usda`). `allPurpose`
    is the C++ name of the empty token, not a value; an empty list names no
    purpose, leaving material resolution to each renderer. USD does not
    enforce `allowedTokens` when authoring.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform token[] materialBindingPurposes = ["full", "allPurpose"]
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
            uniform token[] materialBindingPurposes = ["full", ""]
        }
    }
    ```

    ## Fix safety
    Safe, conditional: `allPurpose`, `all` and `default` become `""` and
    repeats are dropped, keeping the order; other unknown tokens and an empty
    array are not fixed.
    """

    code = "SE011"
    name = "material-binding-purposes-invalid"
    severity = Severity.WARNING
    fix_safety = "safe-conditional"
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        name = "materialBindingPurposes"
        attr = prim.GetAttribute(name)
        purposes = authored_value(attr)
        if purposes is None:
            return
        allowed = allowed_tokens(prim, name)
        if not purposes:
            yield Diagnostic(
                "materialBindingPurposes is an authored empty array, which names no binding "
                'purpose; author e.g. ["full", ""] or remove the opinion',
                at=attr,
            )
            return
        tokens = items(purposes)
        unknown = [t for t in dict.fromkeys(tokens) if t not in allowed]
        repeated = _duplicates(tokens)
        if not unknown and not repeated:
            return
        problems = []
        if unknown:
            problems.append(f"{_quoted(unknown)} not allowed")
        if repeated:
            problems.append(f"{_quoted(repeated)} repeated")
        fix = None
        if all(t in _ALL_PURPOSE_ALIASES for t in unknown):
            mapped = ["" if t in _ALL_PURPOSE_ALIASES else t for t in tokens]
            fixed = Vt.TokenArray(list(dict.fromkeys(mapped)))
            fix = Fix(f"author {_fmt(fixed)}", True, set_value(attr.GetPath(), fixed))
        alias_hint = (
            '; the all-purpose binding is the empty token ""'
            if any(t in _ALL_PURPOSE_ALIASES for t in unknown)
            else ""
        )
        yield Diagnostic(
            f"materialBindingPurposes {_fmt(purposes)}: {', '.join(problems)}{alias_hint}; "
            f"use each of {_quoted(allowed)} at most once",
            at=attr,
            fix=fix,
        )


# -- working colour space (SE012, SE013) -----------------------------------------


def _rendering_color_space(prim: Usd.Prim) -> tuple[Usd.Attribute, str] | None:
    """The authored, non-empty renderingColorSpace (an empty token means unset)."""
    attr = prim.GetAttribute("renderingColorSpace")
    name = authored_value(attr)
    return (attr, str(name)) if name else None


def _color_space_cache(ctx: Context) -> Usd.ColorSpaceCache:
    return ctx.memo("settings.color_space_cache", Usd.ColorSpaceCache)


class RenderingColorSpaceUnknown(Rule):
    """renderingColorSpace is not a colour space USD knows.

    ## What it does
    Checks an authored, non-empty `renderingColorSpace` on a RenderSettings
    with `Usd.ColorSpaceAPI.IsValidColorSpaceName`: valid are the built-in
    `Gf.ColorSpaceNames` tokens (`lin_ap1_scene`, `lin_rec709_scene`, …), the
    display-name aliases `Gf.ColorSpace` accepts (`ACEScg`), and custom spaces
    a `ColorSpaceDefinitionAPI` declares on the settings prim or an ancestor.
    The message lists the nearest canonical tokens.

    ## Why is this bad?
    *"renderingColorSpace: The renderer working color space. This is the
    (linear) color space a renderer should use to do internal calculations"*
    (`RenderSettings.md`); *"OpenUSD, MaterialX, and OCIO have jointly agreed on
    a canonical set of interoperable color spaces"*
    (`docs/user_guides/color_user_guide.rst`). An OCIO config name such as
    `ACES - ACEScg` is not a USD colour space and is not portable.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform token renderingColorSpace = "ACES - ACEScg"
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
            uniform token renderingColorSpace = "lin_ap1_scene"
        }
    }
    ```

    ## Fix safety
    No automatic fix: which space was meant is a guess; the message suggests
    the nearest canonical names.
    """

    code = "SE012"
    name = "rendering-color-space-unknown"
    severity = Severity.WARNING
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        found = _rendering_color_space(prim)
        if found is None:
            return
        attr, name = found
        if _colorspace.is_valid_name(prim, name, _color_space_cache(ctx)):
            return
        nearest = _colorspace.nearest_names(name)
        hint = f"did you mean {_quoted(nearest)}? Otherwise " if nearest else ""
        yield Diagnostic(
            f'renderingColorSpace "{name}" is not a USD colour space (not a Gf.ColorSpace name '
            f"or alias, and no ColorSpaceDefinitionAPI on {prim.GetPath()} or its ancestors "
            f'defines it); {hint}use a canonical linear token such as "lin_ap1_scene"',
            at=attr,
        )


class RenderingColorSpaceNotLinear(Rule):
    """renderingColorSpace is a valid colour space with a non-linear transfer function.

    ## What it does
    Resolves a valid `renderingColorSpace` on a RenderSettings (`Gf.ColorSpace`
    for a built-in name or alias, `ComputeColorSpaceFromDefinitionAttributes`
    for a custom one) and fires when its gamma is not 1 or its linear bias is
    not 0 (`srgb_*`, `g22_*`, `g18_*`, `g24_*`). The data-like spaces `data`,
    `raw`, `identity` and `unknown` do not fire unless the option
    `flag-data-spaces` is set. The message suggests the linear space with the
    same primaries.

    ## Why is this bad?
    *"This is the (linear) color space a renderer should use to do internal
    calculations"* (`RenderSettings.md`); *"Describes a renderer's working
    (linear) colorSpace where all the renderer/shader math is expected to
    happen"* (`pxr/usd/usdRender/schema.usda`). Lighting maths in an encoded
    space gives wrong results.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform token renderingColorSpace = "srgb_rec709_scene"
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
            uniform token renderingColorSpace = "lin_rec709_scene"
        }
    }
    ```

    ## Fix safety
    No automatic fix: changing the working space changes the picture.

    ## Options
    `flag-data-spaces` (bool, default false): also report the data-like
    designations `data`, `raw`, `identity` and `unknown`, which are not colour
    spaces a renderer can work in. Off by default because the user guide's own
    example uses `renderingColorSpace = "raw"` (catalog, Ambiguous semantics 6).
    """

    @dataclass(frozen=True)
    class Options:
        flag_data_spaces: bool = False

    code = "SE013"
    name = "rendering-color-space-not-linear"
    severity = Severity.WARNING
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        found = _rendering_color_space(prim)
        if found is None:
            return
        attr, name = found
        space = _colorspace.resolve(prim, name, _color_space_cache(ctx))
        if space is None:
            return  # SE012's finding
        if space.is_data_like:
            if self.options.flag_data_spaces:
                yield Diagnostic(
                    f'renderingColorSpace "{name}" designates data, not a working colour '
                    'space; use a linear space such as "lin_ap1_scene"',
                    at=attr,
                )
            return
        if space.is_linear:
            return
        linear = _colorspace.linear_counterpart(space)
        suggestion = f'"{linear}" (same primaries)' if linear else 'e.g. "lin_ap1_scene"'
        origin = f", defined on {space.defined_on}" if space.defined_on else ""
        yield Diagnostic(
            f'renderingColorSpace "{name}" is not linear (gamma {space.gamma:.4g}, linear bias '
            f"{space.linear_bias:.4g}{origin}); the working space must be linear: use "
            f"{suggestion}",
            at=attr,
        )


# -- products (SE014, SE015) -----------------------------------------------------


class ProductsTargetInvalid(Rule):
    """A products target is missing, unusable or not a RenderProduct.

    ## What it does
    Resolves each forwarded target of a RenderSettings' `products` and
    reports it when it is not a prim path, no prim exists there, the prim is
    inactive, only an `over` or abstract, or it is not a RenderProduct.

    ## Why is this bad?
    *"This relationship should target UsdRenderProduct prims."*
    (`pxr/usd/usdRender/schema.usda`). `UsdRenderComputeSpec` silently skips a
    target that is not a RenderProduct (`pxr/usd/usdRender/spec.cpp`) and
    Hydra's traversal never sees an unusable one, so that output is never
    rendered.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel products = </Render/Vars/beauty>
        }

        def Scope "Vars"
        {
            def RenderVar "beauty"
            {
                string sourceName = "Ci"
            }
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
            rel products = </Render/Beauty>
        }

        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = </Render/Vars/beauty>
        }

        def Scope "Vars"
        {
            def RenderVar "beauty"
            {
                string sourceName = "Ci"
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: which product was meant cannot be guessed.
    """

    code = "SE014"
    name = "products-target-invalid"
    severity = Severity.ERROR
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        rel = prim.GetRelationship("products")
        for target in resolve_targets(rel):
            problem = typed_target_problem(target, UsdRender.Product, "a RenderProduct")
            if problem is None:
                continue
            yield Diagnostic(
                f"products target {target.path} {problem}, so that output is never rendered; "
                "target a defined, active RenderProduct prim",
                at=rel,
            )


class NoProducts(Rule):
    """A RenderSettings has no products, so the output is renderer-defined.

    ## What it does
    Reports a RenderSettings whose `products` has no forwarded target: the
    relationship is absent, authored empty, or emptied by list-op composition.

    ## Why is this bad?
    *"If no products are provided, renderers should render a default RGB
    image."* (`RenderSettings.md`). Valid, but the output's name and channels
    are then up to the renderer, which a farm submission rarely wants.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform int2 resolution = (1920, 1080)
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
            uniform int2 resolution = (1920, 1080)
            rel products = </Render/Beauty>
        }

        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
        }
    }
    ```

    ## Fix safety
    No automatic fix: the outputs are a pipeline decision.
    """

    code = "SE015"
    name = "no-products"
    severity = Severity.INFO
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        rel = prim.GetRelationship("products")
        if forwarded_targets(rel):
            return
        authored = bool(rel) and rel.HasAuthoredTargets()
        state = "is empty" if authored else "is not authored"
        yield Diagnostic(
            f"RenderSettings {prim.GetPath()} has no products (products {state}); renderers "
            "then write a default RGB image with a name of their choosing: target the "
            "RenderProducts to write, e.g. rel products = </Render/Products/beauty>",
            at=rel if authored else prim,
        )


# -- authoring mistakes on every render prim (SE016, SE017) ----------------------

#: Every render prim kind: SE016 and SE017 look at all their schema attributes.
_RENDER_PRIM_TYPES = (UsdRender.SettingsBase, UsdRender.Var, UsdRender.Pass)
_NOT_CONVERTIBLE = object()


def _convert_scalar(value: Any, like: Any) -> Any:
    """``value`` as the Python type of ``like`` when no information is lost."""
    if isinstance(like, Sdf.AssetPath) and isinstance(value, str):
        return Sdf.AssetPath(value)  # a string path is an unresolved asset path
    if isinstance(like, bool):
        ok = isinstance(value, bool) or (isinstance(value, int) and value in (0, 1))
        return bool(value) if ok else _NOT_CONVERTIBLE
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        if isinstance(like, str) and isinstance(value, str):
            return str(value)  # string and token hold the same text
        return _NOT_CONVERTIBLE
    if isinstance(like, int):
        integral = math.isfinite(value) and float(value).is_integer()
        return int(value) if integral and abs(value) < 2**31 else _NOT_CONVERTIBLE
    if isinstance(like, float):
        # double -> float keeps the value within float precision (catalog SE016)
        return float(value) if not math.isfinite(value) or abs(value) < 3.4e38 else _NOT_CONVERTIBLE
    return _NOT_CONVERTIBLE


def _convert(value: Any, type_name: Sdf.ValueTypeName) -> Any:
    """``value`` re-typed as ``type_name`` when that is lossless, else _NOT_CONVERTIBLE."""
    like = type_name.defaultValue
    if type_name.isArray:
        if isinstance(value, str) or not hasattr(value, "__len__"):
            return _NOT_CONVERTIBLE
        items = [_convert(v, type_name.scalarType) for v in value]
        return _NOT_CONVERTIBLE if _NOT_CONVERTIBLE in items else type(like)(items)
    if isinstance(like, (bool, int, float, str, Sdf.AssetPath)):
        return _convert_scalar(value, like)
    if hasattr(like, "__len__") and hasattr(value, "__len__") and not isinstance(value, str):
        if len(value) != len(like):
            return _NOT_CONVERTIBLE
        items = [_convert_scalar(v, like[0]) for v in value]
        return _NOT_CONVERTIBLE if _NOT_CONVERTIBLE in items else type(like)(*items)
    return _NOT_CONVERTIBLE


def _spec_values(spec: Sdf.AttributeSpec) -> tuple[Any, dict[float, Any]]:
    """A spec's default (None when it has none) and its time samples."""
    default = spec.default if spec.HasDefaultValue() else None
    layer, path = spec.layer, spec.path
    samples = {t: layer.QueryTimeSample(path, t) for t in layer.ListTimeSamplesForPath(path)}
    return default, samples


def _retyped_values(
    spec: Sdf.AttributeSpec, type_name: Sdf.ValueTypeName
) -> tuple[Any, dict[float, Any]] | None:
    """The spec's default and samples converted to ``type_name``, or None when
    a value would not survive the conversion (value blocks are kept)."""
    default, samples = _spec_values(spec)
    converted = {}
    for key, value in [("default", default), *samples.items()]:
        if value is None or isinstance(value, Sdf.ValueBlock):
            converted[key] = value
            continue
        new = _convert(value, type_name)
        if new is _NOT_CONVERTIBLE:
            return None
        converted[key] = new
    new_default = converted.pop("default")
    return new_default, converted


def _retype_spec(attr_path: Sdf.Path, type_name: Sdf.ValueTypeName) -> Apply:
    """Re-author the edit target's spec of an attribute with the schema type."""

    def apply(stage: Usd.Stage) -> None:
        spec = stage.GetEditTarget().GetAttributeSpecForScenePath(attr_path)
        values = _retyped_values(spec, type_name) if spec else None
        if values is None:
            return
        default, samples = values
        owner, name, variability = spec.owner, spec.name, spec.variability
        owner.RemoveProperty(spec)
        new = Sdf.AttributeSpec(owner, name, type_name, variability)
        if default is not None:
            new.default = default
        for time, value in samples.items():
            new.layer.SetTimeSample(new.path, time, value)

    return apply


def _authored_schema_attributes(
    prim: Usd.Prim, ctx: Context
) -> tuple[tuple[Usd.Attribute, Usd.PrimDefinition.Attribute], ...]:
    """The prim's authored attributes that its schema declares, with their
    definitions: SE016 and SE017 both walk them, so they are listed once per lint."""

    def compute() -> tuple[tuple[Usd.Attribute, Usd.PrimDefinition.Attribute], ...]:
        attribute_definition = prim.GetPrimDefinition().GetAttributeDefinition
        found = []
        for attr in prim.GetAuthoredAttributes():
            definition = attribute_definition(attr.GetName())
            if definition:  # custom attributes have none
                found.append((attr, definition))
        return tuple(found)

    return ctx.memo(("settings.authored_schema_attributes", prim), compute)


class AttributeTypeMismatch(Rule):
    """A schema attribute of a render prim is authored with the wrong type.

    ## What it does
    For every authored attribute of a RenderSettings, RenderProduct, RenderVar
    or RenderPass whose name the prim definition declares, reports the
    strongest spec in the property stack whose type differs from the schema
    type (e.g. `float2 resolution`, `string productName`, `token sourceName`),
    as `usdValidation:AttributeTypeMismatch` does, even when a stronger
    well-typed opinion currently hides it. Every other rule treats such an
    opinion as unauthored, so one mistake gives one finding.

    ## Why is this bad?
    Schema types: `resolution` int2, `pixelAspectRatio` float, `dataWindowNDC`
    float4, `productName` token, `sourceName` string
    (`pxr/usd/usdRender/schema.usda`). A typed C++ read cannot store a
    mistyped value (`SdfAbstractDataTypedValue::StoreValue` sets
    `typeMismatch`, `pxr/usd/sdf/abstractData.h`), so C++ renderers lose the
    opinion without a diagnostic while Python tools see it.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform float2 resolution = (1920, 1080)
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
            uniform int2 resolution = (1920, 1080)
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when every value of the mistyped spec converts without
    loss (`float2 (1920, 1080)` to `int2`, `string` to `token`, `double4` to
    `float4` within float precision), the fix re-authors the spec with the
    schema type in the same layer; its other metadata is not carried over.
    """

    code = "SE016"
    name = "attribute-type-mismatch"
    severity = Severity.ERROR
    fix_safety = "safe-conditional"
    prim_types = _RENDER_PRIM_TYPES

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        for attr, definition in _authored_schema_attributes(prim, ctx):
            specs = mismatched_specs(attr)
            if not specs:
                continue
            schema_type = definition.GetTypeName()
            spec = specs[0]
            where = spec.layer.GetDisplayName()
            hidden = (
                ""
                if spec == mismatched_spec(attr)
                else (" (a stronger well-typed opinion hides it for now)")
            )
            fix = None
            if _retyped_values(spec, schema_type) is not None:
                fix = Fix(
                    f"re-author as {schema_type} in {where}",
                    True,
                    _retype_spec(attr.GetPath(), schema_type),
                )
            yield Diagnostic(
                f"{attr.GetName()} is authored as {spec.typeName} in {where}{hidden} but the "
                f"{prim.GetTypeName()} schema declares {schema_type}; C++ consumers drop "
                f"the value: author it as {schema_type}",
                at=attr,
                fix=fix,
                layer=spec.layer,
            )


#: Where a value comes from when the attribute has time samples or a spline
#: (GetResolveInfo() without a time: samples beat a default of the same layer).
_VARYING_SOURCES = frozenset(
    {
        Usd.ResolveInfoSourceTimeSamples,
        Usd.ResolveInfoSourceValueClips,
        Usd.ResolveInfoSourceSpline,
    }
)


def _first_sampled_layer(attr: Usd.Attribute) -> Sdf.Layer | None:
    """The layer whose time samples supply the attribute's value."""
    for spec in attr.GetPropertyStack(DEFAULT_TIME):
        if spec.layer.GetNumTimeSamplesForPath(spec.path):
            return spec.layer
    return None


def _samples_to_default(attr_path: Sdf.Path, value: Any) -> Apply:
    def apply(stage: Usd.Stage) -> None:
        attr = stage.GetAttributeAtPath(attr_path)
        attr.Clear()  # default and samples in the edit target
        attr.Set(value)

    return apply


class TimeSamplesIgnored(Rule):
    """A uniform render attribute has time samples, which spec-based consumers ignore.

    ## What it does
    Reports (a) a schema attribute of a render prim that the schema declares
    `uniform` but that has time samples or a spline, and (b) a RenderProduct's
    `productName`, the only varying render attribute, that has time samples but
    no default value.

    ## Why is this bad?
    Every usdRender setting is declared `uniform`
    (`pxr/usd/usdRender/schema.usda`) and `UsdRenderComputeSpec` reads them at
    `UsdTimeCode::Default()` (`pxr/usd/usdRender/spec.cpp`). With only samples
    authored, the Default read returns the **fallback** (resolution
    (2048, 1080)) while frame reads return the samples, and because the
    attribute counts as authored, a product override made only of samples
    replaces the settings value with the product's fallback. USD does not
    enforce `uniform`: *"Variability is a statement of intent but doesn't
    control behavior"* (`pxr/usd/usd/stage.cpp`).

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform int2 resolution.timeSamples = {
                1001: (1920, 1080),
            }
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
            uniform int2 resolution = (1920, 1080)
        }
    }
    ```

    ## Fix safety
    Safe, conditional: for a uniform attribute whose samples all hold the same
    value (and whose default, if any, equals it), the fix replaces them with
    that default value in the layer holding the samples. Varying samples and
    `productName` are not fixed.
    """

    code = "SE017"
    name = "time-samples-ignored"
    severity = Severity.WARNING
    fix_safety = "safe-conditional"
    prim_types = _RENDER_PRIM_TYPES

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        for attr, definition in _authored_schema_attributes(prim, ctx):
            # Both findings need samples or a spline, which few attributes have:
            # the value's source says so in one call (the count and HasSpline()
            # are two), and that comes before the dearer type check.
            if attr.GetResolveInfo().GetSource() not in _VARYING_SOURCES:
                continue
            count = attr.GetNumTimeSamples()
            if (not count and not attr.HasSpline()) or mismatched_spec(attr) is not None:
                continue  # nothing to report, or SE016's finding
            if definition.GetVariability() == Sdf.VariabilityUniform:
                yield from self._uniform(attr, count, ctx)
            elif attr.GetName() == "productName" and prim.IsA(UsdRender.Product):
                yield from self._product_name(attr, count)

    def _uniform(self, attr: Usd.Attribute, count: int, ctx: Context) -> Iterator[Diagnostic]:
        if attr.HasSpline():
            yield Diagnostic(
                f"uniform {attr.GetName()} is authored as a spline, but renderers read it once "
                f"at the default time (getting {_fmt(attr.Get())}); author a single default "
                "value instead",
                at=attr,
            )
            return
        if count == 0:
            return
        first = time_samples(attr, 1)[0]
        times = time_samples(attr, ctx.time_sample_cap)
        values = [attr.Get(t) for t in times]
        layer = _first_sampled_layer(attr)
        default_spec = next(
            (s for s in attr.GetPropertyStack(DEFAULT_TIME) if s.layer == layer), None
        )
        default = default_spec.default if default_spec and default_spec.HasDefaultValue() else None
        fix = None
        uniform_value = len(times) == count and all(v == values[0] for v in values)
        if uniform_value and default in (None, values[0]):
            fix = Fix(
                f"replace the samples with the default value {_fmt(values[0])}",
                True,
                _samples_to_default(attr.GetPath(), values[0]),
            )
        shown = (
            _fmt(values[0]) if uniform_value else f"{len(set(map(str, values)))} distinct values"
        )
        yield Diagnostic(
            f"uniform {attr.GetName()} has {count} time sample(s) ({shown}) from "
            f"{first:g}, but renderers read it once at the default time and get "
            f"{_fmt(attr.Get())}; author one default value instead of time samples",
            at=attr,
            fix=fix,
            layer=layer,
        )

    def _product_name(self, attr: Usd.Attribute, count: int) -> Iterator[Diagnostic]:
        if count == 0:
            return
        source = attr.GetResolveInfo(DEFAULT_TIME).GetSource()
        if source == Usd.ResolveInfoSourceDefault:
            return
        first = time_samples(attr, 1)[0]
        yield Diagnostic(
            f"productName has time samples (first {_fmt(attr.Get(first))} at {first:g}) but no "
            f"default, so consumers reading at the default time get {_fmt(attr.Get())}; "
            "author a default productName as well",
            at=attr,
            layer=_first_sampled_layer(attr),
        )


RULES = (
    ResolutionNonPositive,
    PixelAspectRatioInvalid,
    DataWindowMalformed,
    DataWindowOutsideAperture,
    DataWindowCropOrOverscan,
    AspectRatioConformPolicyInvalid,
    InstantaneousShutterDeprecated,
    InstantaneousShutterConflict,
    IncludedPurposesInvalid,
    IncludedPurposesMissingDefault,
    MaterialBindingPurposesInvalid,
    RenderingColorSpaceUnknown,
    RenderingColorSpaceNotLinear,
    ProductsTargetInvalid,
    NoProducts,
    AttributeTypeMismatch,
    TimeSamplesIgnored,
)
