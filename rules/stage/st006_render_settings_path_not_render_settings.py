"""ST006 render-settings-path-not-render-settings."""

from __future__ import annotations

from collections.abc import Iterator

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import describe_prim_type, unusable_reason

from ._settings_path import _settings_path_problem, settings_path_opinion


class RenderSettingsPathNotRenderSettings(Rule):
    """renderSettingsPrimPath names a prim that is not a usable RenderSettings.

    ## What it does
    Reports an authored `renderSettingsPrimPath` naming an existing prim that
    is not a RenderSettings (a RenderProduct, a Scope, ...), or a RenderSettings
    that is inactive, only an `over`, or abstract (a `class`).

    ## Why is this bad?
    `UsdRenderSettings::GetStageRenderSettings()` returns an invalid prim *"If
    unauthored, or the metadata does not refer to a valid UsdRenderSettings
    prim"* (`pxr/usd/usdRender/settings.h`). For an inactive or abstract
    RenderSettings it still returns a valid object (usd-core 26.11), but Hydra
    never populates such prims, so consumers disagree.

    ## Example
    ```usda
    #usda 1.0
    (
        renderSettingsPrimPath = "/Render/Product"
    )

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel products = </Render/Product>
        }

        def RenderProduct "Product"
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
            rel products = </Render/Product>
        }

        def RenderProduct "Product"
        {
        }
    }
    ```

    ## Fix safety
    No automatic fix: which settings was meant is unknown.
    """

    code = "ST006"
    name = "render-settings-path-not-render-settings"
    severity = Severity.ERROR
    partial_composition = True

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        opinion = settings_path_opinion(ctx)
        if opinion is None or not opinion[0]:
            return
        value, layer = opinion
        if _settings_path_problem(ctx.stage, value) is not None:
            return  # ST005's finding
        prim = ctx.stage.GetPrimAtPath(value)
        if not prim.IsA(schemas.RenderSettings):
            what = f"{describe_prim_type(prim)}, not a RenderSettings"
        else:
            reason = unusable_reason(prim)
            if reason is None:
                return
            what = f"a RenderSettings that {reason}"
        yield Diagnostic(
            message=f'renderSettingsPrimPath "{value}" names {what}; renderers find no usable '
            "default settings. Name a defined, active RenderSettings prim",
            layer=layer,
        )
