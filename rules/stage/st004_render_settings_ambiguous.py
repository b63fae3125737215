"""ST004 render-settings-ambiguous."""

from __future__ import annotations

from collections.abc import Iterator

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas

from ._settings_path import settings_path_opinion


class RenderSettingsAmbiguous(Rule):
    """Several RenderSettings and no renderSettingsPrimPath choosing one.

    ## What it does
    Reports a stage whose root and session layers author no (or an empty)
    `renderSettingsPrimPath` while it holds two or more usable RenderSettings,
    and lists them.

    ## Why is this bad?
    *"A UsdStage may contain multiple UsdRenderSettings prims representing
    distinct groups of settings. A settings prim may be nominated as a useful
    default in layer metadata using the `renderSettingsPrimPath` field."*
    (`pxr/usd/usdRender/overview.dox`). Without it every tool picks its own
    (first found, last found, or none), so farm and viewport renders differ.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Final"
        {
        }

        def RenderSettings "Preview"
        {
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0
    (
        renderSettingsPrimPath = "/Render/Final"
    )

    def Scope "Render"
    {
        def RenderSettings "Final"
        {
        }

        def RenderSettings "Preview"
        {
        }
    }
    ```

    ## Fix safety
    No automatic fix: a person must choose the default settings.
    """

    code = "ST004"
    name = "render-settings-ambiguous"
    severity = Severity.WARNING
    partial_composition = True

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        opinion = settings_path_opinion(ctx)
        settings = ctx.prims_of(schemas.RenderSettings)
        if (opinion is not None and opinion[0]) or len(settings) < 2:
            return
        candidates = ", ".join(f"<{p.GetPath()}>" for p in settings)
        yield Diagnostic(
            message=f"the stage has {len(settings)} RenderSettings ({candidates}) and no "
            "renderSettingsPrimPath, so each tool picks its own; author "
            "renderSettingsPrimPath in the root layer naming the default one",
        )
