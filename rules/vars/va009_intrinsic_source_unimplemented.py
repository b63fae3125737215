"""VA009 intrinsic-source-unimplemented."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas

from .._aov import checked_value


class IntrinsicSourceUnimplemented(Rule):
    """A RenderVar uses the unimplemented sourceType intrinsic.

    ## What it does
    Reports a RenderVar whose composed `sourceType` is `intrinsic`.

    ## Why is this bad?
    *"intrinsic": This setting is currently unimplemented, but represents a
    future namespace for UsdRender to provide portable baseline RenderVars,
    such as camera depth, that may have varying implementations for each
    renderer.* (`pxr/usd/usdRender/schema.usda`). No renderer can be expected
    to honour it yet.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "depth"
            {
                token dataType = "float"
                string sourceName = "depth"
                uniform token sourceType = "intrinsic"
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
            def RenderVar "depth"
            {
                token dataType = "float"
                string sourceName = "z"
                uniform token sourceType = "raw"
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: the renderer's own source name for the quantity is
    needed.
    """

    code = "VA009"
    name = "intrinsic-source-unimplemented"
    severity = Severity.INFO
    partial_composition = True
    prim_types = (schemas.RenderVar,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        if checked_value(prim, "sourceType", ctx) != "intrinsic":
            return
        yield Diagnostic(
            message=f'sourceType "intrinsic" of RenderVar {prim.GetPath()} is reserved and not yet '
            'implemented: no renderer is expected to produce it; use sourceType "raw" (or '
            '"lpe") with the renderer\'s own source name',
            at=prim.GetAttribute("sourceType"),
        )
