"""VA001 source-name-empty."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values

from .._aov import checked_value


class SourceNameEmpty(Rule):
    """A RenderVar's sourceName is empty.

    ## What it does
    Reports a usable RenderVar whose composed `sourceName` (`uniform string`,
    fallback `""`) is empty: left unauthored, authored `""` or blocked. A
    type-mismatched opinion (e.g. `token sourceName`) is SE016's finding.

    ## Why is this bad?
    *"The renderer should look for an output of this name as the computed
    value for the RenderVar."* (`pxr/usd/usdRender/schema.usda`). With `raw`
    the empty string reaches the renderer as-is, with `lpe` it is an empty
    expression, and hdPrman uses `sourceName` as the channel name of non-LPE
    vars (`third_party/renderman-26/plugin/hdPrman/renderParam.cpp`).

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "normal"
            {
                token dataType = "normal3f"
            }
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "normal"
            {
                token dataType = "normal3f"
                string sourceName = "Nn"
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: only the author knows which output the var should read.

    ## Profiles
    A renderer profile may name var properties that define the var's output
    in place of `sourceName` (the `moonray` profile:
    `parameters:moonray:result`, which hdMoonray copies onto the MoonRay
    RenderOutput); a var authoring one is no finding under that profile.
    """

    code = "VA001"
    name = "source-name-empty"
    severity = Severity.ERROR
    partial_composition = True
    prim_types = (schemas.RenderVar,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        if checked_value(prim, "sourceName", ctx) != "":
            return
        names = prim_values(prim).authored_names()
        if any(ctx.profile_accepts(prim, "var_output", n) for n in names):
            return  # the renderer reads the var's output from its own settings (R2-5)
        attr = prim.GetAttribute("sourceName")
        what = (
            "light path expression" if checked_value(prim, "sourceType", ctx) == "lpe" else "output"
        )
        yield Diagnostic(
            message=f"RenderVar {prim.GetPath()} has an empty sourceName: the renderer gets no "
            f"{what} "
            'to compute; author the source it should read, e.g. string sourceName = "Ci"',
            at=attr if attr.IsAuthored() else prim,
        )
