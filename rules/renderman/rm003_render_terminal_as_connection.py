"""RM003 ri-render-terminal-as-connection."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas

from ._terminals import TERMINALS, connection_form, conversion_fix, relationship_form
from ._terminals import relationship_form_evidence as evidence


class RenderTerminalAsConnection(Rule):
    """A RenderSettings connects a render terminal where its RenderMan expects a relationship.

    ## What it does
    Under the `renderman` profile, and only where something says the
    stage's RenderMan expects the relationship form, reports a
    RenderSettings that names its integrator, sample filters or display
    filters with attribute connections (`outputs:ri:integrator.connect`,
    `outputs:ri:sampleFilters.connect`, `outputs:ri:displayFilters.connect`)
    instead of the relationships `ri:integrator`, `ri:sampleFilters`,
    `ri:displayFilters`. What says so: the schema registry where the linter
    runs declares `rel ri:integrator` on RenderSettings (RenderMan's
    `PxrRenderTerminalsAPI` of that version), or the stage itself authors the
    relationship form of a terminal (on any RenderSettings, or `rel
    ri:projection` on a render camera). Without either, the connection form
    is RenderMan's own (OpenUSD's `renderman-26` schema) and is not reported.

    ## Why is this bad?
    It is the condition of OpenUSD's validator
    `rmanUsdValidators:PxrRenderTerminalsAPIRelationships` (OpenUSD
    `third_party/renderman-26/plugin/rmanUsdValidators`, a warning: *"Found a
    PxrRenderTerminalsAPI unsupported attribute (...) that should instead be
    a relationship"*), which reports it only where the registered schema has
    the relationships (its test, `testenv/testRmanUsdValidators.cpp`, expects
    the warning exactly when the RenderSettings definition declares
    `ri:integrator`). usdImaging then reads the relationships and uses the
    connections only when no relationship target exists, with a warning
    that they are deprecated (`UsdImagingRenderSettingsAdapter::Populate`,
    `pxr/usdImaging/usdImaging/renderSettingsAdapter.cpp`, while
    `LEGACY_PXR_RENDER_TERMINALS_API_ALLOWED_AND_WARN` is true; a future
    release disallows them). A connection next to a relationship target,
    from any layer, is ignored already.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel ri:integrator = </Render/PathTracer>
            token outputs:ri:displayFilters.connect = </Render/Background.outputs:result>
        }

        def PxrPathTracer "PathTracer"
        {
            token outputs:result
        }

        def PxrBackgroundDisplayFilter "Background"
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
            rel ri:integrator = </Render/PathTracer>
            rel ri:displayFilters = </Render/Background>
        }

        def PxrPathTracer "PathTracer"
        {
            token outputs:result
        }

        def PxrBackgroundDisplayFilter "Background"
        {
            token outputs:result
        }
    }
    ```

    ## Fix safety
    Safe when the terminal's relationship has no targets: the fix authors
    the relationship with the connected prims as its targets and removes the
    connection, in the layer that holds it (as the validator's fixer
    `ConvertRenderTerminalsAttrsToRels` does, with prim paths as OpenUSD's
    own test stages write them), so what renders stays the same. Unsafe when
    the relationship already has targets: usdImaging renders those and
    ignores the connection, and the fix would make the connection's targets
    win instead.
    """

    code = "RM003"
    name = "ri-render-terminal-as-connection"
    severity = Severity.WARNING
    partial_composition = True
    profile = "renderman"
    prim_types = (schemas.RenderSettings,)
    fix_safety = "safe-conditional"

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        for terminal in TERMINALS:
            form = connection_form(prim, terminal)
            if form is None:
                continue
            why = evidence(ctx)
            if why is None:
                return
            targets = ", ".join(f"<{p}>" for p in form.paths)
            relationship = relationship_form(prim, terminal)
            effect = (
                f"; it is ignored, since {terminal.relationship} already targets "
                + ", ".join(f"<{p}>" for p in relationship.paths)
                if relationship is not None
                else "; usdImaging still reads it, with a deprecation warning"
            )
            yield Diagnostic(
                message=f"{form.prop.GetPath()} connects the {terminal.what} ({targets}) as "
                f"an attribute, a form this RenderMan no longer supports ({why}){effect}. "
                f"Author rel {terminal.relationship} instead",
                at=form.prop,
                fix=conversion_fix(form, safe=relationship is None),
            )
