"""SE007 instantaneous-shutter-deprecated."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values

from ._fixes import Apply


def _replace_instantaneous_shutter(prim_path: Sdf.Path, author_disable: bool) -> Apply:
    def apply(stage: Usd.Stage) -> None:
        prim = stage.GetPrimAtPath(prim_path)
        if author_disable:
            from pxr import UsdRender  # the schema API, imported only when a fix runs (start-up)

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
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = (schemas.RenderSettingsBase,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        if not values.has_value("instantaneousShutter"):
            return
        attr = values.attribute("instantaneousShutter")
        value = bool(attr.Get())
        fix = None
        if not value:
            fix = Fix(
                description="remove the deprecated instantaneousShutter opinion",
                safe=True,
                apply=_replace_instantaneous_shutter(prim.GetPath(), False),
            )
        elif not values.has_value("disableMotionBlur"):
            fix = Fix(
                description="replace with disableMotionBlur = true (same result only when the "
                "camera's "
                "shutter:open is 0)",
                safe=True,
                apply=_replace_instantaneous_shutter(prim.GetPath(), True),
            )
        advice = "author disableMotionBlur = true instead" if value else "remove it"
        yield Diagnostic(
            message=f"instantaneousShutter = {str(value).lower()} is deprecated and ignored by "
            f"OpenUSD's render consumers; {advice}",
            at=attr,
            fix=fix,
        )
