"""VA004 primvar-source-not-found."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas

from .._aov import checked_value

#: Where the render prims live by convention; primvars there are not scene data.
RENDER_SCOPE = Sdf.Path("/Render")
PRIMVARS_PREFIX = "primvars:"


def _scene_primvars(ctx: Context) -> frozenset[str]:
    return _scene_primvar_names(ctx.stage)


def _scene_primvar_names(stage: Usd.Stage) -> frozenset[str]:
    """Names of the primvars with authored values on any prim outside /Render,
    instance prototypes included (each prototype once)."""
    from pxr import UsdGeom  # its bindings cost start-up; only a primvar RenderVar needs them

    names: set[str] = set()
    roots = [stage.Traverse(), *(Usd.PrimRange(p) for p in stage.GetPrototypes())]
    for prims in roots:
        iterator = iter(prims)
        for prim in iterator:
            if prim.GetPath() == RENDER_SCOPE:
                iterator.PruneChildren()
                continue
            for primvar in UsdGeom.PrimvarsAPI(prim).GetPrimvarsWithAuthoredValues():
                names.add(str(primvar.GetPrimvarName()))
    return frozenset(names)


class PrimvarSourceNotFound(Rule):
    """A primvar-sourced RenderVar names a primvar no prim has.

    ## What it does
    For a RenderVar whose composed `sourceType` is `primvar`, takes
    `sourceName` (minus an optional `primvars:` prefix) and reports it when no
    prim outside `/Render` has a primvar of that name with an authored value.
    The scene's primvars are collected once per stage, and only when such a
    RenderVar exists; the rule is skipped on stages opened with a population
    mask, where the scene is not all there.

    ## Why is this bad?
    *"primvar": This source represents the name of a primvar. Some renderers
    may use this to ensure that the primvar is provided; other renderers may
    require that a suitable material network be provided, in which case this
    is simply an advisory setting.* (`pxr/usd/usdRender/schema.usda`). The
    setting can be advisory and primvars can arrive from payloads not loaded
    at lint time, hence info only.

    ## Example
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Mesh "card"
        {
            texCoord2f[] primvars:st = [(0, 0), (1, 0), (1, 1), (0, 1)] (
                interpolation = "vertex"
            )
        }
    }

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "uv"
            {
                token dataType = "float2"
                string sourceName = "uv"
                uniform token sourceType = "primvar"
            }
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Mesh "card"
        {
            texCoord2f[] primvars:st = [(0, 0), (1, 0), (1, 1), (0, 1)] (
                interpolation = "vertex"
            )
        }
    }

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "uv"
            {
                token dataType = "float2"
                string sourceName = "st"
                uniform token sourceType = "primvar"
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: the primvar may come from a payload or a material.
    """

    code = "VA004"
    name = "primvar-source-not-found"
    severity = Severity.INFO
    partial_composition = True
    prim_types = (schemas.RenderVar,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        if checked_value(prim, "sourceType", ctx) != "primvar":
            return
        source = checked_value(prim, "sourceName", ctx)
        if not source:
            return
        # The engine's partial stage holds only the render prims: ask for the
        # whole scene. A stage the user masked (catalog: --render-only) is skipped.
        ctx.require_full_stage()
        if not ctx.stage.GetPopulationMask().IncludesSubtree("/"):
            return
        name = source.removeprefix(PRIMVARS_PREFIX)
        names = ctx.cached(_scene_primvars)
        if name in names:
            return
        yield Diagnostic(
            message=f"no prim outside {RENDER_SCOPE} has a primvar {name!r} (RenderVar "
            f"{prim.GetPath()} "
            "reads it); check the spelling, or ignore this if the primvar comes from an "
            "unloaded payload or the material network",
            at=prim.GetAttribute("sourceName"),
        )
