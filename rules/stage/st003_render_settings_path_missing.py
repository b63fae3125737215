"""ST003 render-settings-path-missing."""

from __future__ import annotations

from collections.abc import Iterator

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas

from ._settings_path import _single_settings_fix, settings_path_opinion


class RenderSettingsPathMissing(Rule):
    """The stage has one RenderSettings but no renderSettingsPrimPath names it.

    ## What it does
    Reports a stage whose root and session layers author no (or an empty)
    `renderSettingsPrimPath` while it holds exactly one usable RenderSettings.

    ## Why is this bad?
    *"Always provide a 'default' RenderSettings. ... Communicate to a renderer
    what the default RenderSettings is by using the `renderSettingsPrimPath`
    metadata in your stage's root layer"* (`pxr/usd/usdRender/userDoc/overview.md`).
    `UsdRenderSettings::GetStageRenderSettings()` consults only this metadata
    (`pxr/usd/usdRender/settings.cpp`) and returns nothing without it.

    ## Example
    ```usda
    #usda 1.0

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
    Safe: the fix authors `renderSettingsPrimPath` naming the only
    RenderSettings in the root layer's metadata (never in a sublayer, where
    it is ignored; see ST007).
    """

    code = "ST003"
    name = "render-settings-path-missing"
    severity = Severity.INFO
    partial_composition = True
    fix_safety = "safe"

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        opinion = settings_path_opinion(ctx)
        settings = ctx.prims_of(schemas.RenderSettings)
        if (opinion is not None and opinion[0]) or len(settings) != 1:
            return
        path = settings[0].GetPath()
        state = "is empty" if opinion is not None else "is not set"
        yield Diagnostic(
            message=f"stage metadata renderSettingsPrimPath {state}, so "
            f"UsdRenderSettings.GetStageRenderSettings() finds no settings although the stage "
            f'has one, <{path}>; author renderSettingsPrimPath = "{path}" in the root layer',
            fix=_single_settings_fix(ctx, "author"),
        )
