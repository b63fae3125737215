"""KA002 karma-frame-token-missing."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import authored_value

from ._husk import NOT_WRITTEN

#: The frame variable in both of Houdini's spellings: $F (also $F4, $FF) and the
#: protected ${F} (${F4}) that lets a letter follow it (Houdini docs, Expressions
#: in file names, https://www.sidefx.com/docs/houdini/render/expressions.html).
FRAME_VARIABLES = ("$F", "${F")


def _frame_range(stage: Usd.Stage) -> tuple[float, float] | None:
    """The authored [start, end] of the root layer when it spans frames."""
    layer = stage.GetRootLayer()
    if not (layer.HasStartTimeCode() and layer.HasEndTimeCode()):
        return None
    start, end = stage.GetStartTimeCode(), stage.GetEndTimeCode()
    return (start, end) if end > start else None


class FrameTokenMissing(Rule):
    """An animated shot writes every frame to the same productName.

    ## What it does
    Under the `karma` profile, on a stage whose root layer authors a
    `startTimeCode` before its `endTimeCode`, reports a RenderProduct whose
    `productName` has no time samples and contains no `$F` frame variable
    (nor its protected form `${F}`).

    ## Why is this bad?
    *"Include $F in the file name to insert the frame number. This is necessary
    when rendering animation."* (Houdini docs, Karma Render Settings LOP,
    Output Picture, https://www.sidefx.com/docs/houdini/nodes/lop/karmarendersettings.html).
    husk renders each frame of the range to the product's name; a name with
    neither a frame variable nor a value per frame is overwritten by every
    frame when each frame is its own husk run (the USD Render ROP's default),
    and only the last one survives. A husk run of several frames refuses it
    instead: *"Rendering N frames. The output '...' should have variables to
    prevent overwriting."* and renders nothing (`XUSD_RenderProduct::expandProduct`,
    `src/houdini/lib/H_USD/HUSD/XUSD_RenderSettings.C` in SideFX's
    HoudiniUsdBridge).

    ## Example
    ```usda
    #usda 1.0
    (
        startTimeCode = 1001
        endTimeCode = 1100
    )

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            int karma:global:samplesperpixel = 9
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
    (
        startTimeCode = 1001
        endTimeCode = 1100
    )

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            int karma:global:samplesperpixel = 9
            rel products = </Render/Beauty>
        }

        def RenderProduct "Beauty"
        {
            token productName = "beauty.$F4.exr"
        }
    }
    ```

    ## Fix safety
    No automatic fix: where the frame number goes in the name is a pipeline
    convention.
    """

    code = "KA002"
    name = "karma-frame-token-missing"
    severity = Severity.WARNING
    partial_composition = True
    profile = "karma"
    prim_types = (schemas.RenderProduct,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        frames = _frame_range(ctx.stage)
        if frames is None:
            return
        attr = prim.GetAttribute("productName")
        if attr.GetNumTimeSamples():
            return
        name = authored_value(attr)
        if not name or any(v in str(name) for v in FRAME_VARIABLES) or str(name) in NOT_WRITTEN:
            return  # empty: PR001's; no file at all: KA001's
        yield Diagnostic(
            message=f"productName {str(name)!r} of {prim.GetPath()} has no $F and no value per "
            f"frame, so every frame of {frames[0]:g}-{frames[1]:g} overwrites the same file "
            '(a husk run of several frames refuses it: the output "should have variables to '
            'prevent overwriting"); '
            f'include the frame, e.g. "{str(name).rsplit(".", 1)[0]}.$F4.exr"',
            at=attr,
        )
