"""PR008 deep-raster-missing-alpha."""

from __future__ import annotations

from collections.abc import Callable, Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, record, schemas
from usdrender_lint.api.resolve import resolve_target

from .._aov import checked_value, product_render_vars


def _append_target(rel_path: Sdf.Path, target: Sdf.Path) -> Callable[[Usd.Stage], None]:
    def apply(stage: Usd.Stage) -> None:
        stage.GetRelationshipAtPath(rel_path).AddTarget(target, Usd.ListPositionBackOfAppendList)

    return apply


ALPHA_NAMES = frozenset({"a", "alpha"})
FOUR_CHANNEL_TYPES = frozenset({"color4f", "color4h", "color4d", "float4", "half4", "double4"})


def _is_alpha_source(var: Usd.Prim, ctx: Context) -> bool:
    source = checked_value(var, "sourceName", ctx) or ""
    return (
        var.GetName().lower() in ALPHA_NAMES
        or source.lower() in ALPHA_NAMES
        or checked_value(var, "dataType", ctx) in FOUR_CHANNEL_TYPES
    )


class DeepRasterMissingAlpha(Rule):
    """A deepRaster product has no alpha RenderVar.

    ## What it does
    Reports a usable RenderProduct whose composed `productType` is
    `deepRaster`, that has at least one valid RenderVar, and none of whose
    RenderVars is an alpha source: no var whose prim name or `sourceName` is
    `a` or `alpha` (any case) and none with a 4-channel `dataType`
    (`color4f/color4h/color4d/float4/half4/double4`).

    ## Why is this bad?
    *"Every color or auxiliary channel in a deep image must have an associated
    alpha channel."* (OpenEXR, `website/InterpretingDeepPixels.rst`). Z is
    normally emitted by the deep display driver itself; alpha must be
    requested as a RenderVar, otherwise deep merge and flatten cannot
    composite the samples.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Deep"
        {
            token productName = "deep.exr"
            uniform token productType = "deepRaster"
            rel orderedVars = </Render/Vars/color>
        }

        def Scope "Vars"
        {
            def RenderVar "color"
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
        def RenderProduct "Deep"
        {
            token productName = "deep.exr"
            uniform token productType = "deepRaster"
            rel orderedVars = [</Render/Vars/color>, </Render/Vars/alpha>]
        }

        def Scope "Vars"
        {
            def RenderVar "color"
            {
                string sourceName = "Ci"
            }

            def RenderVar "alpha"
            {
                token dataType = "float"
                string sourceName = "a"
            }
        }
    }
    ```

    ## Fix safety
    Safe, conditional: only when the pipeline configures its default alpha
    RenderVar (option `alpha-var`, a prim path) and that prim is a usable
    alpha RenderVar on the stage does the fix append it to `orderedVars`; by
    default there is no fix. (The catalog's class: none, pipeline default
    vars.)

    ## Options
    `alpha-var` (prim path, default empty: no fix): the RenderVar the fix
    appends, e.g. `"/Render/Vars/alpha"`.
    """

    code = "PR008"
    name = "deep-raster-missing-alpha"
    severity = Severity.WARNING
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = (schemas.RenderProduct,)

    @record(frozen=True)
    class Options:
        alpha_var: str = ""

    def _alpha_fix(self, product: Usd.Prim, ctx: Context) -> Fix | None:
        path = self.options.alpha_var
        if not path or not Sdf.Path.IsValidPathString(path):
            return None
        target = resolve_target(product.GetStage(), Sdf.Path(path))
        var = target.usable_prim
        if var is None or not var.IsA(schemas.RenderVar):
            return None
        if not _is_alpha_source(var, ctx):
            return None
        rel_path = product.GetRelationship("orderedVars").GetPath()
        return Fix(
            description=f"append <{path}> to orderedVars",
            safe=True,
            apply=_append_target(rel_path, target.path),
        )

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        if checked_value(prim, "productType", ctx) != "deepRaster":
            return
        render_vars = product_render_vars(prim, ctx)
        if not render_vars or any(_is_alpha_source(v, ctx) for v in render_vars):
            return
        yield Diagnostic(
            message=f"deep RenderProduct {prim.GetPath()} has no alpha RenderVar (none named a or "
            "alpha "
            "by prim name or sourceName, none with a 4-channel dataType): deep samples cannot "
            'be composited; add a RenderVar with sourceName "a" and dataType "float" to '
            "orderedVars",
            at=prim,
            fix=self._alpha_fix(prim, ctx),
        )
