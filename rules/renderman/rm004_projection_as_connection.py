"""RM004 ri-projection-as-connection."""

from __future__ import annotations

from collections.abc import Iterator

from usdrender_lint.api import Context, Diagnostic, Rule, Severity

from .._camera import effective_cameras
from ._terminals import PROJECTION, connection_form, conversion_fix, relationship_form
from ._terminals import relationship_form_evidence as evidence


class ProjectionAsConnection(Rule):
    """A render camera connects its RenderMan projection where a relationship is expected.

    ## What it does
    Under the `renderman` profile, and only where something says the
    stage's RenderMan expects the relationship form, reports a render
    camera (the effective camera of a configuration) that names its
    RenderMan projection with an attribute connection
    (`outputs:ri:projection.connect`) instead of the relationship
    `ri:projection`. What says so: the schema registry where the linter
    runs declares `rel ri:projection` on `PxrCameraProjectionAPI`, or the
    stage authors the relationship form of a RenderMan terminal (`rel
    ri:projection` on a render camera, `rel ri:integrator`, ... on a
    RenderSettings). Without either, the connection form is RenderMan's own
    (OpenUSD's `renderman-26` schema) and is not reported.

    ## Why is this bad?
    It is the condition of OpenUSD's validator
    `rmanUsdValidators:PxrCameraProjectionAPIRelationships` (OpenUSD
    `third_party/renderman-26/plugin/rmanUsdValidators`, a warning: *"Found a
    PxrCameraProjectionAPI unsupported attribute (outputs:ri:projection)
    that should instead be a relationship (ri:projection)"*), which reports
    it only when the registered `PxrCameraProjectionAPI` declares the
    relationship (its test: `rmanUsdValidators/testenv/testRmanUsdValidators.cpp`):
    a RenderMan of that schema reads the projection from the relationship
    and not from the connection.

    ## Example
    ```usda
    #usda 1.0

    def Camera "Cam"
    {
        token outputs:ri:projection.connect = </Cam/Fisheye.outputs:result>

        def PxrCamera "Fisheye"
        {
            token outputs:result
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </Cam>
            rel ri:integrator = </Render/PathTracer>
        }

        def PxrPathTracer "PathTracer"
        {
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Camera "Cam"
    {
        rel ri:projection = </Cam/Fisheye>

        def PxrCamera "Fisheye"
        {
            token outputs:result
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </Cam>
            rel ri:integrator = </Render/PathTracer>
        }

        def PxrPathTracer "PathTracer"
        {
        }
    }
    ```

    ## Fix safety
    Safe when `ri:projection` has no targets: the fix authors the
    relationship with the connected prim as its target and removes the
    connection, in the layer that holds it (as the validator's fixer
    `ConvertPxrCameraProjectionAttrToRel` does), so what renders stays the
    same. Unsafe when the relationship already has targets: the fix would
    replace them with the connection's.
    """

    code = "RM004"
    name = "ri-projection-as-connection"
    severity = Severity.WARNING
    partial_composition = True
    profile = "renderman"
    fix_safety = "safe-conditional"

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for use in effective_cameras(ctx):
            form = connection_form(use.prim, PROJECTION)
            if form is None:
                continue
            why = evidence(ctx)
            if why is None:
                return
            relationship = relationship_form(use.prim, PROJECTION)
            targets = ", ".join(f"<{p}>" for p in form.paths)
            yield Diagnostic(
                message=f"{form.prop.GetPath()} connects the RenderMan projection ({targets}) "
                f"as an attribute, a form this RenderMan no longer supports ({why}). Author "
                "rel ri:projection instead",
                at=form.prop,
                fix=conversion_fix(form, safe=relationship is None),
            )
