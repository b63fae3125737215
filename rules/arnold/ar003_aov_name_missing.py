"""AR003 arnold-aov-name-missing."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import authored_value, resolve_targets

AOV_NAME = "driver:parameters:aov:name"


class AovNameMissing(Rule):
    """A RenderVar of an Arnold-type product has no driver:parameters:aov:name.

    ## What it does
    Under the `arnold` profile, for a RenderProduct whose `productType` is
    `arnold` (written by arnold-usd's own driver), reports each usable RenderVar
    of its `orderedVars` that has no non-empty `driver:parameters:aov:name`.

    ## Why is this bad?
    For these products husk hands arnold-usd each var with its settings, and
    arnold-usd takes the AOV's name from `driver:parameters:aov:name` only
    (*"name is not coming through as a top parameter"*); a var without one is
    not added to the product (`!renderVar.name.empty()` in
    `_ParseDelegateRenderProducts`, `libs/render_delegate/render_delegate.cpp`).
    The image is written without that AOV.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            uniform token productType = "arnold"
            rel orderedVars = </Render/Vars/diffuse>
        }

        def Scope "Vars"
        {
            def RenderVar "diffuse"
            {
                string sourceName = "diffuse"
            }
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            uniform token productType = "arnold"
            rel orderedVars = </Render/Vars/diffuse>
        }

        def Scope "Vars"
        {
            def RenderVar "diffuse"
            {
                string driver:parameters:aov:name = "diffuse"
                string sourceName = "diffuse"
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: the channel name is the pipeline's (often the var's
    sourceName, but not always).
    """

    code = "AR003"
    name = "arnold-aov-name-missing"
    severity = Severity.ERROR
    partial_composition = True
    profile = "arnold"
    prim_types = (schemas.RenderProduct,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        if str(authored_value(prim.GetAttribute("productType")) or "") != "arnold":
            return
        for target in resolve_targets(prim.GetRelationship("orderedVars")):
            var = target.prim
            if not target.ok or var is None or not var.IsA(schemas.RenderVar):
                continue
            name = var.GetAttribute(AOV_NAME)
            if name and name.Get():
                continue
            yield Diagnostic(
                message=f"RenderVar {var.GetPath()} of the arnold-type product {prim.GetPath()} "
                f"has no {AOV_NAME}, so arnold-usd drops it from the image; author "
                f'string {AOV_NAME} = "{var.GetName()}"',
                at=var,
            )
