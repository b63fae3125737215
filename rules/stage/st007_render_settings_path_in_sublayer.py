"""ST007 render-settings-path-in-sublayer."""

from __future__ import annotations

import itertools
from collections.abc import Iterator

from pxr import Pcp, Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity

from ._settings_path import RENDER_SETTINGS_PATH_KEY, _set_settings_path, settings_path_opinion


def _root_layer_stack_rank(stage: Usd.Stage) -> dict[Sdf.Layer, int]:
    return {layer: rank for rank, layer in enumerate(stage.GetLayerStack(False))}


_ARC_WORDS = {Pcp.ArcTypeReference: "referenced layer", Pcp.ArcTypePayload: "payload layer"}


def _how_used(stage: Usd.Stage, layers: list[Sdf.Layer]) -> dict[Sdf.Layer, str]:
    """How each of ``layers`` reaches the stage, named in a phrase: a sublayer
    (of the root or session layer), a referenced or payload layer or a
    sublayer of one, else a value clip layer (the only other way a layer is
    used: clips and their manifests are opened apart from any arc)."""
    stack = set(stage.GetLayerStack(True))
    said = {layer: f"sublayer {layer.GetDisplayName()}" for layer in layers if layer in stack}
    wanted = {layer for layer in layers if layer not in stack}
    # Only when a finding needs it (rare): the walk reads every prim's index.
    prims = itertools.chain(
        stage.TraverseAll(),
        *(Usd.PrimRange(p, Usd.PrimAllPrimsPredicate) for p in stage.GetPrototypes()),
    )
    for prim in prims if wanted else ():
        index = prim.GetPrimIndex()
        if not index.IsValid():  # a prototype's root: its instances' indexes hold its arcs
            continue
        nodes = [index.rootNode]
        while nodes:
            node = nodes.pop()
            nodes.extend(node.children)
            arc = _ARC_WORDS.get(node.arcType)
            if arc is None:
                continue
            arc_layers = node.layerStack.layers
            top = arc_layers[0].GetDisplayName()
            for layer in wanted.intersection(arc_layers):
                name = layer.GetDisplayName()
                said[layer] = (
                    f"{arc} {name}"
                    if layer == arc_layers[0]
                    else f"sublayer {name} of the {arc} {top}"
                )
            wanted.difference_update(arc_layers)
        if not wanted:
            break
    said.update({layer: f"value clip layer {layer.GetDisplayName()}" for layer in wanted})
    return said


class RenderSettingsPathInSublayer(Rule):
    """renderSettingsPrimPath is authored in a layer whose metadata the stage ignores.

    ## What it does
    Reports every layer the stage uses, other than its root and session
    layers, whose metadata authors a non-empty `renderSettingsPrimPath`:
    sublayers, referenced and payload layers (and their sublayers), and value
    clip layers; the message says which. Composition ignores that opinion
    (`stage.GetMetadata` does not see it). A value the root or session
    layer already authors identically is redundant, not lost, and is not
    reported (that is also what the fix leaves behind).

    ## Why is this bad?
    *"Like all stage metadata, `renderSettingsPrimPath` can be authoredin a
    stage's root layer or session layer, but no other subLayers of the root
    layer."* (`pxr/usd/usdRender/overview.dox`, typo verbatim). Shot layers
    that sublayer a sequence render layer lose its default settings without
    any message.

    ## Example
    ```usda
    #usda 1.0
    (
        subLayers = [
            @./render_layer.usda@
        ]
    )
    ```

    with `render_layer.usda`:

    ```usda render_layer.usda
    #usda 1.0
    (
        renderSettingsPrimPath = "/Render/Settings"
    )

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0
    (
        renderSettingsPrimPath = "/Render/Settings"
    )

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when neither the root nor the session layer authors the
    field, the fix copies the strongest sublayer's value into the root layer
    metadata (the sublayer opinion is inert and may stay). Otherwise, and for
    referenced, payload and value clip layers, there is no fix.
    """

    code = "ST007"
    name = "render-settings-path-in-sublayer"
    severity = Severity.WARNING
    partial_composition = True
    fix_safety = "safe-conditional"

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        stage = ctx.stage
        ignored = {stage.GetRootLayer(), stage.GetSessionLayer()}
        inert = [
            (layer, str(layer.pseudoRoot.GetInfo(RENDER_SETTINGS_PATH_KEY)))
            for layer in stage.GetUsedLayers()
            if layer not in ignored and layer.pseudoRoot.HasInfo(RENDER_SETTINGS_PATH_KEY)
        ]
        opinion = settings_path_opinion(ctx)
        effective = opinion[0] if opinion is not None else None
        inert = [(layer, value) for layer, value in inert if value and value != effective]
        if not inert:
            return  # most stages: no layer stack or arc needs naming
        rank = _root_layer_stack_rank(stage)
        inert.sort(key=lambda item: (rank.get(item[0], len(rank)), item[0].identifier))
        # Only the strongest sublayer opinion is what the author most likely meant.
        fixable = opinion is None and inert and inert[0][0] in rank
        used = _how_used(stage, [layer for layer, _ in inert])
        for index, (layer, value) in enumerate(inert):
            fix = None
            if fixable and index == 0:
                fix = Fix(
                    description=f'copy renderSettingsPrimPath = "{value}" into the root layer',
                    safe=True,
                    apply=_set_settings_path(value),
                    layer=stage.GetRootLayer(),
                )
            advice = (
                "author it in the root layer"
                if effective is None
                else f'the stage uses "{effective}"; remove the ignored value'
            )
            yield Diagnostic(
                message=f'renderSettingsPrimPath "{value}" is authored in the {used[layer]}, '
                "where the stage ignores it (only the root and session "
                f"layers count); {advice}",
                layer=layer,
                fix=fix,
            )
