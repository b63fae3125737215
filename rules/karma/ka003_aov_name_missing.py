"""KA003 karma-aov-name-missing."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values

from .._aov import product_render_vars

AOV_NAME = "driver:parameters:aov:name"
#: The husk-only spelling newer husk releases read first.
HUSK_AOV_NAME = "driver:parameters:aov:husk:name"


class AovNameMissing(Rule):
    """A RenderVar husk renders has no driver:parameters:aov:name.

    ## What it does
    Under the `karma` profile, reports each usable RenderVar in a
    RenderProduct's `orderedVars` that authors neither
    `driver:parameters:aov:name` nor husk's own
    `driver:parameters:aov:husk:name`.

    ## Why is this bad?
    husk takes the name of each var's AOV from that attribute and from nothing
    else: when a var of a product it renders has none, it reports *"Missing
    driver:parameters:aov:name token in RenderVar"* and the render settings
    fail to load, so nothing is rendered (`XUSD_RenderVar::loadFrom`,
    `src/houdini/lib/H_USD/HUSD/XUSD_RenderSettings.C` in SideFX's
    HoudiniUsdBridge). Houdini's Render Var LOP always authors it; a var
    written by another tool often does not.

    ## Example
    ```usda
    #usda 1.0

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
        def RenderSettings "Settings"
        {
            int karma:global:samplesperpixel = 9
            rel products = </Render/Beauty>
        }

        def RenderProduct "Beauty"
        {
            token productName = "beauty.$F4.exr"
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
    No automatic fix: the AOV name is the pipeline's (often the var's
    sourceName, but not always).
    """

    code = "KA003"
    name = "karma-aov-name-missing"
    severity = Severity.ERROR
    partial_composition = True
    profile = "karma"
    prim_types = (schemas.RenderProduct,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        for var in product_render_vars(prim, ctx):
            values = prim_values(var)
            if values.has_value(AOV_NAME) or values.has_value(HUSK_AOV_NAME):
                continue
            yield Diagnostic(
                message=f"RenderVar {var.GetPath()} of {prim.GetPath()} has no {AOV_NAME}, "
                'which husk needs of every var it renders ("Missing '
                f'{AOV_NAME} token in RenderVar"), so it renders nothing; author '
                f'string {AOV_NAME} = "{var.GetName()}"',
                at=var,
            )
