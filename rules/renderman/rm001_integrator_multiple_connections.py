"""RM001 ri-integrator-multiple-connections."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas

from ._terminals import INTEGRATOR


class IntegratorMultipleConnections(Rule):
    """The RenderSettings connects more than one integrator.

    ## What it does
    Under the `renderman` profile, reports a RenderSettings whose
    `outputs:ri:integrator` has more than one authored connection.

    ## Why is this bad?
    hdPrman reads the connections of `outputs:ri:integrator` and hands RenderMan
    only the first (`paths.front()` in `HdPrman_RenderSettings::_Sync`, OpenUSD
    `third_party/renderman-26/plugin/hdPrman/renderSettings.cpp`): a render has
    one integrator. The others are ignored silently, and which one renders
    depends on the order of list edits across layers.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            token outputs:ri:integrator.connect = [
                </Render/PathTracer.outputs:result>,
                </Render/Direct.outputs:result>,
            ]
        }

        def "PathTracer"
        {
            token outputs:result
        }

        def "Direct"
        {
            token outputs:result
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
            token outputs:ri:integrator.connect = </Render/PathTracer.outputs:result>
        }

        def "PathTracer"
        {
            token outputs:result
        }
    }
    ```

    ## Fix safety
    No automatic fix: which integrator was meant is the author's choice.
    """

    code = "RM001"
    name = "ri-integrator-multiple-connections"
    severity = Severity.WARNING
    partial_composition = True
    profile = "renderman"
    prim_types = (schemas.RenderSettings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute(INTEGRATOR)
        sources = attr.GetConnections() if attr else []
        if len(sources) > 1:
            listed = ", ".join(f"<{p}>" for p in sources)
            yield Diagnostic(
                message=f"{attr.GetPath()} connects {len(sources)} integrators ({listed}); "
                f"hdPrman renders with the first, <{sources[0].GetPrimPath()}>, and ignores "
                "the others: keep one connection",
                at=attr,
            )
