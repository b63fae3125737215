"""SE: RenderSettingsBase and RenderSettings attributes."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd, UsdRender

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity
from usdrender_lint.resolve import EffectiveValue, composed_value, has_authored_value, is_finite

from ._raster import pixel_centres


def _data_window_problem(window, resolution) -> str | None:
    """Why an authored dataWindowNDC renders nothing sensible, or None."""
    xmin, ymin, xmax, ymax = (float(c) for c in window)
    if not is_finite(window):
        return "has a NaN or infinite component"
    if xmin >= xmax or ymin >= ymax:
        axis = "x" if xmin >= xmax else "y"
        return f"is inverted or empty on {axis} (min must be < max)"
    width, height = int(resolution[0]), int(resolution[1])
    if width > 0 and height > 0 and (
        pixel_centres(xmin, xmax, width) == 0 or pixel_centres(ymin, ymax, height) == 0
    ):
        return f"contains no pixel centre at resolution {width}x{height}"
    return None


def _swap_x(attr_path: Sdf.Path):
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
        units: list[tuple[EffectiveValue, object]] = []
        for config in ctx.configurations:
            units.append((config.effective("dataWindowNDC"),
                          config.effective("resolution").value))
        for settings in ctx.prims_of(UsdRender.Settings):
            attr = settings.GetAttribute("dataWindowNDC")
            if has_authored_value(attr):
                units.append((EffectiveValue(attr.Get(), attr, True),
                              composed_value(settings, "resolution")))
        for product in ctx.untargeted_products:
            attr = product.GetAttribute("dataWindowNDC")
            if has_authored_value(attr):
                units.append((EffectiveValue(attr.Get(), attr, True),
                              composed_value(product, "resolution")))
        for window, resolution in units:
            if not window.authored:
                continue
            problem = _data_window_problem(window.value, resolution)
            if problem is None:
                continue
            xmin, _, xmax, _ = window.value
            fix = None
            if "inverted" in problem and is_finite(window.value) and xmin > xmax:
                fix = Fix("swap xmin and xmax", False, _swap_x(window.attr.GetPath()))
            yield Diagnostic(
                f"dataWindowNDC {tuple(round(float(c), 6) for c in window.value)} {problem}; "
                "use (xmin, ymin, xmax, ymax) with min < max, e.g. (0, 0, 1, 1)",
                at=window.attr,
                fix=fix,
            )


def _replace_instantaneous_shutter(prim_path: Sdf.Path, author_disable: bool):
    def apply(stage: Usd.Stage) -> None:
        prim = stage.GetPrimAtPath(prim_path)
        if author_disable:
            UsdRender.SettingsBase(prim).CreateDisableMotionBlurAttr().Set(True)
        prim.RemoveProperty("instantaneousShutter")

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
            fix = Fix("remove the deprecated instantaneousShutter opinion", True,
                      _replace_instantaneous_shutter(prim.GetPath(), False))
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


RULES = (DataWindowMalformed, InstantaneousShutterDeprecated)
