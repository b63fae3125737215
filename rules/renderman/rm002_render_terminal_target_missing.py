"""RM002 ri-render-terminal-target-missing."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas

from ._terminals import TERMINALS, forms, target_problem


class RenderTerminalTargetMissing(Rule):
    """A RenderSettings names an integrator or filter that is not on the stage or not one.

    ## What it does
    Under the `renderman` profile, reports each target of a RenderSettings'
    integrator, sample filter or display filter terminal, in either form (the
    relationships `ri:integrator`, `ri:sampleFilters`, `ri:displayFilters` or
    the connections of `outputs:ri:integrator`, `outputs:ri:sampleFilters`,
    `outputs:ri:displayFilters`), whose prim does not exist on the composed
    stage, is not usable (inactive, `over`-only, abstract), is typeless, or
    has a type the schema registry knows that is not the terminal's
    RenderMan type (a `Shader`, a `Scope`, ...).

    ## Why is this bad?
    hdPrman takes the integrator and the sample and display filters from
    these terminals (`HdPrman_RenderSettings::_ProcessRenderTerminals`, OpenUSD
    `third_party/renderman-26/plugin/hdPrman/renderSettings.cpp`), and
    usdImaging populates each target only through the prim adapter of its
    type, which RenderMan registers for its usdRiPxr types
    (`UsdImagingRenderSettingsAdapter::Populate`,
    `pxr/usdImaging/usdImaging/renderSettingsAdapter.cpp`). A target that is
    not there, or not such a type, renders without that filter, or with
    RenderMan's default integrator instead of the one the shot asked for,
    and nothing fails.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            token outputs:ri:integrator.connect = </Render/Integrator.outputs:result>
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
            token outputs:ri:integrator.connect = </Render/Integrator.outputs:result>
        }

        def PxrPathTracer "Integrator"
        {
            token outputs:result
        }
    }
    ```

    ## Fix safety
    No automatic fix: only the author knows which integrator or filter was meant.
    """

    code = "RM002"
    name = "ri-render-terminal-target-missing"
    severity = Severity.ERROR
    partial_composition = True
    profile = "renderman"
    prim_types = (schemas.RenderSettings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        for terminal in TERMINALS:
            for form in forms(prim, terminal):
                verb = "targets" if form.is_relationship else "connects"
                for path in form.paths:
                    problem = target_problem(ctx.stage, path, terminal)
                    if problem is None:
                        continue
                    yield Diagnostic(
                        message=f"{form.prop.GetPath()} {verb} <{path}>, which {problem}; "
                        f"hdPrman {terminal.effect()}. Name an existing RenderMan "
                        f"{terminal.what}",
                        at=form.prop,
                    )
