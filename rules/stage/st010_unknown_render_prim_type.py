"""ST010 unknown-render-prim-type."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity

from ._render_prims import RENDER_SCOPE

#: Concrete usdRender type names, the candidates for a misspelt type.
RENDER_TYPE_NAMES = ("RenderSettings", "RenderProduct", "RenderVar", "RenderPass")


def edit_distance(a: str, b: str) -> int:
    """Levenshtein distance: insertions, deletions and substitutions."""
    previous = list(range(len(b) + 1))
    for i, char_a in enumerate(a, 1):
        current = [i]
        for j, char_b in enumerate(b, 1):
            current.append(
                min(previous[j] + 1, current[j - 1] + 1, previous[j - 1] + (char_a != char_b))
            )
        previous = current
    return previous[-1]


def _retype(prim_path: Sdf.Path, type_name: str):
    def apply(stage: Usd.Stage) -> None:
        stage.GetPrimAtPath(prim_path).SetTypeName(type_name)

    return apply


def _type_name_spec(prim: Usd.Prim) -> Sdf.PrimSpec | None:
    """The strongest spec authoring the prim's type name."""
    return next((spec for spec in prim.GetPrimStack() if spec.typeName), None)


class UnknownRenderPrimType(Rule):
    """A prim under /Render, or with a Render... type name, has an unregistered type.

    ## What it does
    Reports a usable prim whose type name is not empty but names no registered
    schema, when the prim is under `/Render` or its type name starts with
    `Render` (any case). It suggests the closest usdRender type name
    (`RenderSettings`, `RenderProduct`, `RenderVar`, `RenderPass`) by edit
    distance. Under a renderer profile, the types that renderer's own
    schemas define are not reported (`renderman`: `Pxr*`, hdPrman's usdRiPxr
    schemas; `arnold`: `Arnold*`, arnold-usd's schemas such as
    `ArnoldNodeGraph`; `omniverse`: the omni_sensors types such as `OmniLidar`).

    ## Why is this bad?
    USD composes an unknown type as a typeless prim, so `def RenderSetting` or
    `def RenderVars` is not a RenderSettings or RenderVar and every schema-based
    consumer skips it (`IsA` is false; usd-core 26.11). It also fires when the
    renderer plugin that registers a custom render type is not installed where
    you lint.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSetting "Settings"
        {
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
        }
    }
    ```

    ## Fix safety
    Unsafe: when exactly one usdRender type is closest and within edit distance
    2, the fix rewrites the type name in the layer of the stage's layer stack
    that authors it; the prim then starts to take part in renders. Otherwise
    (or when the type comes through a reference) there is no fix.
    """

    code = "ST010"
    name = "unknown-render-prim-type"
    severity = Severity.WARNING
    partial_composition = True
    fix_safety = "unsafe"

    #: Farther than this, a usdRender type name is no plausible suggestion.
    suggestion_distance = 3
    fix_distance = 2

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for prim in ctx.unknown_type_prims:
            type_name = prim.GetTypeName()
            path = prim.GetPath()
            if not (path.HasPrefix(RENDER_SCOPE) or type_name.lower().startswith("render")):
                continue
            if ctx.profile_accepts(prim, "prim_type", type_name):
                continue  # the renderer's own schema defines it (R2-5)
            ranked = sorted((edit_distance(type_name, c), c) for c in RENDER_TYPE_NAMES)
            (distance, closest), (runner_up, _) = ranked[0], ranked[1]
            if distance <= self.suggestion_distance:
                advice = f"did you mean {closest}?"
            else:
                advice = (
                    "if a renderer plugin defines this type, install it where you lint; "
                    "otherwise use a usdRender type"
                )
            fix = None
            spec = _type_name_spec(prim)
            if (
                distance <= self.fix_distance
                and runner_up > distance
                and spec is not None
                and spec.path == path
                and ctx.stage.HasLocalLayer(spec.layer)
            ):
                fix = Fix(
                    description=f"retype <{path}> as {closest}",
                    safe=False,
                    apply=_retype(path, closest),
                    layer=spec.layer,
                )
            what = "is not a registered schema here"
            if not Usd.SchemaRegistry.GetTypeFromName(type_name).isUnknown:
                # e.g. `def RenderSettingsBase`: registered, but abstract.
                what = "is an abstract schema, which cannot type a prim"
                advice = f"use a concrete type such as {closest}"
            yield Diagnostic(
                message=f"type '{type_name}' of <{path}> {what}, so USD "
                f"composes it as a typeless prim that schema-based consumers skip; {advice}",
                at=prim,
                fix=fix,
                layer=spec.layer if spec is not None else None,
            )
