"""SE008 instantaneous-shutter-conflict."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values


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
    partial_composition = True
    prim_types = (schemas.RenderSettingsBase,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        if (
            values.authored("instantaneousShutter") is True
            and values.authored("disableMotionBlur") is False
        ):
            yield Diagnostic(
                message="instantaneousShutter = true asks for no motion blur but "
                "disableMotionBlur = "
                "false asks for it; OpenUSD ignores instantaneousShutter, so this renders WITH "
                "motion blur: remove instantaneousShutter and set disableMotionBlur to the "
                "intended value",
                at=values.attribute("instantaneousShutter"),
            )
