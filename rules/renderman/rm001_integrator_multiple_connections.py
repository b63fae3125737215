"""RM001 ri-integrator-multiple-connections."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas

from ._terminals import INTEGRATOR, forms


class IntegratorMultipleConnections(Rule):
    """The RenderSettings names more than one integrator.

    ## What it does
    Under the `renderman` profile, reports a RenderSettings whose integrator
    terminal names more than one prim, in either of its forms: the
    relationship `ri:integrator` with several targets, or the attribute
    `outputs:ri:integrator` with several connections.

    ## Why is this bad?
    hdPrman hands RenderMan only the first integrator it is given
    (`paths.front()` in `HdPrman_RenderSettings::_ProcessRenderTerminals`,
    OpenUSD `third_party/renderman-26/plugin/hdPrman/renderSettings.cpp`): a
    render has one integrator. usdImaging passes on every target of the
    relationship, or of the connection when no relationship target exists
    (`UsdImagingRenderSettingsAdapter::Populate`,
    `pxr/usdImaging/usdImaging/renderSettingsAdapter.cpp`). The others are
    ignored silently, and which one renders depends on the order of list
    edits across layers.

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

        def PxrPathTracer "PathTracer"
        {
            token outputs:result
        }

        def PxrDirectLighting "Direct"
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

        def PxrPathTracer "PathTracer"
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
        for form in forms(prim, INTEGRATOR):
            if len(form.paths) < 2:
                continue
            listed = ", ".join(f"<{p}>" for p in form.paths)
            verb = "targets" if form.is_relationship else "connects"
            yield Diagnostic(
                message=f"{form.prop.GetPath()} {verb} {len(form.paths)} integrators "
                f"({listed}); hdPrman renders with the first, <{form.paths[0]}>, and ignores "
                f"the others: keep one {form.describe()}",
                at=form.prop,
            )
