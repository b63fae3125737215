"""RM002 ri-render-terminal-target-missing."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import resolve_target

from ._terminals import INTEGRATOR, TERMINALS


class RenderTerminalTargetMissing(Rule):
    """A RenderSettings connects an integrator or filter that is not on the stage.

    ## What it does
    Under the `renderman` profile, reports each connection of a RenderSettings'
    `outputs:ri:integrator`, `outputs:ri:sampleFilters` or
    `outputs:ri:displayFilters` whose prim does not exist on the composed
    stage or is not usable (inactive, `over`-only, abstract).

    ## Why is this bad?
    hdPrman takes the integrator and the sample and display filters from these
    connections (`HdPrman_RenderSettings::_Sync`, OpenUSD
    `third_party/renderman-26/plugin/hdPrman/renderSettings.cpp`) and looks the
    connected prims up in the render index. A connection to a prim that is not
    there renders without that filter, or with RenderMan's default integrator
    instead of the one the shot asked for, and nothing fails.

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

        def "Integrator"
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
        for name in TERMINALS:
            attr = prim.GetAttribute(name)
            if not attr:
                continue
            for source in attr.GetConnections():
                target = resolve_target(ctx.stage, source.GetPrimPath())
                if target.ok:
                    continue
                effect = (
                    "renders with RenderMan's default integrator"
                    if name == INTEGRATOR
                    else "renders without that filter"
                )
                yield Diagnostic(
                    message=f"{attr.GetPath()} connects <{source}>, whose prim "
                    f"{target.problem}; hdPrman {effect}. Connect an existing prim",
                    at=attr,
                )
