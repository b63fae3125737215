"""ST005 render-settings-path-unresolved."""

from __future__ import annotations

from collections.abc import Iterator

from usdrender_lint.api import Context, Diagnostic, Rule, Severity

from ._settings_path import _settings_path_problem, _single_settings_fix, settings_path_opinion


class RenderSettingsPathUnresolved(Rule):
    """renderSettingsPrimPath names no prim.

    ## What it does
    Reports an authored, non-empty `renderSettingsPrimPath` (root or session
    layer) that is not a valid path, is relative (`Render/Settings`), is not a
    prim path (a property path, `/`), or names no prim on the composed stage.

    ## Why is this bad?
    The metadata *"encodes the path to UsdRenderSettingsPrim to use for
    rendering"* (`pxr/usd/usdRender/schema.usda`);
    `UsdRenderSettings::GetStageRenderSettings()` returns an invalid prim *"If
    unauthored, or the metadata does not refer to a valid UsdRenderSettings
    prim"* (`pxr/usd/usdRender/settings.h`), and the render silently uses
    renderer defaults.

    ## Example
    ```usda
    #usda 1.0
    (
        renderSettingsPrimPath = "/Render/PrimarySettings"
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
    Safe, conditional: when the stage has exactly one usable RenderSettings and
    the value is authored in the root layer, the fix rewrites it to name that
    prim. Otherwise there is no fix.
    """

    code = "ST005"
    name = "render-settings-path-unresolved"
    severity = Severity.ERROR
    partial_composition = True
    fix_safety = "safe-conditional"

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        opinion = settings_path_opinion(ctx)
        if opinion is None or not opinion[0]:
            return
        value, layer = opinion
        problem = _settings_path_problem(ctx.stage, value)
        if problem is None:
            return
        fix = _single_settings_fix(ctx, "rewrite to") if layer == ctx.stage.GetRootLayer() else None
        yield Diagnostic(
            message=f'renderSettingsPrimPath "{value}" {problem}, so renderers find no default '
            "RenderSettings; name an existing RenderSettings prim by its absolute path",
            layer=layer,
            fix=fix,
        )
