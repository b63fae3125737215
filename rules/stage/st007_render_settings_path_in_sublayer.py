"""ST007 render-settings-path-in-sublayer."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity

from ._settings_path import RENDER_SETTINGS_PATH_KEY, _set_settings_path, settings_path_opinion


def _root_layer_stack_rank(stage: Usd.Stage) -> dict[Sdf.Layer, int]:
    return {layer: rank for rank, layer in enumerate(stage.GetLayerStack(False))}


class RenderSettingsPathInSublayer(Rule):
    """renderSettingsPrimPath is authored in a layer whose metadata the stage ignores.

    ## What it does
    Reports every layer the stage uses, other than its root and session
    layers, whose metadata authors a non-empty `renderSettingsPrimPath`:
    sublayers, and referenced or payloaded layers. Composition ignores that
    opinion (`stage.GetMetadata` does not see it). A value the root or session
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
    referenced layers, there is no fix.
    """

    code = "ST007"
    name = "render-settings-path-in-sublayer"
    severity = Severity.WARNING
    partial_composition = True
    fix_safety = "safe-conditional"

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        stage = ctx.stage
        ignored = {stage.GetRootLayer(), stage.GetSessionLayer()}
        rank = _root_layer_stack_rank(stage)
        inert = [
            (layer, str(layer.pseudoRoot.GetInfo(RENDER_SETTINGS_PATH_KEY)))
            for layer in stage.GetUsedLayers()
            if layer not in ignored and layer.pseudoRoot.HasInfo(RENDER_SETTINGS_PATH_KEY)
        ]
        opinion = settings_path_opinion(ctx)
        effective = opinion[0] if opinion is not None else None
        inert = [(layer, value) for layer, value in inert if value and value != effective]
        inert.sort(key=lambda item: (rank.get(item[0], len(rank)), item[0].identifier))
        # Only the strongest sublayer opinion is what the author most likely meant.
        fixable = opinion is None and inert and inert[0][0] in rank
        for index, (layer, value) in enumerate(inert):
            fix = None
            if fixable and index == 0:
                fix = Fix(
                    description=f'copy renderSettingsPrimPath = "{value}" into the root layer',
                    safe=True,
                    apply=_set_settings_path(value),
                    layer=stage.GetRootLayer(),
                )
            kind = "sublayer" if layer in rank else "referenced layer"
            advice = (
                "author it in the root layer"
                if effective is None
                else f'the stage uses "{effective}"; remove the ignored value'
            )
            yield Diagnostic(
                message=f'renderSettingsPrimPath "{value}" is authored in the {kind} '
                f"{layer.GetDisplayName()}, where the stage ignores it (only the root and session "
                f"layers count); {advice}",
                layer=layer,
                fix=fix,
            )
