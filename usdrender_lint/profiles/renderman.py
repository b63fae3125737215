"""``renderman``: RenderMan through hdPrman (OpenUSD's third_party/renderman-*)."""

from __future__ import annotations

from .model import Accepted, Profile

USD_RI_PXR = "OpenUSD third_party/renderman-26/plugin/usdRiPxr/schema.usda"
#: hdPrman asks for the render settings in one namespace, "ri".
HD_PRMAN_NAMESPACES = (
    "OpenUSD third_party/renderman-26/plugin/hdPrman/renderDelegate.cpp "
    "(HdPrmanRenderDelegate::GetRenderSettingsNamespaces: ri)"
)
#: The applied API schema whose outputs:ri:integrator, outputs:ri:sampleFilters
#: and outputs:ri:displayFilters connect the settings to hdPrman's render terminals.
RENDER_TERMINALS = (
    "OpenUSD pxr/usdImaging/usdRiPxrImaging/pxrRenderTerminalHelper.h (PxrRenderTerminalsAPI)"
)

RENDERMAN = Profile(
    name="renderman",
    description="RenderMan through hdPrman: the schema plus hdPrman's render terminals "
    "(RM rules) and RenderMan's own prim types.",
    family="RM",
    namespaces=("ri:", "outputs:ri:"),
    api_schemas=("Pxr*",),
    evidence_sources=(HD_PRMAN_NAMESPACES, RENDER_TERMINALS, USD_RI_PXR),
    prim_types=(
        Accepted(
            name="Pxr*",
            why="RenderMan's integrators, sample and display filters are typed prims "
            "(PxrPathTracer, PxrMurkFilter, ...) that hdPrman's usdRiPxr schemas register; "
            "they are unknown types only where RenderMan is not installed",
            source=USD_RI_PXR,
        ),
    ),
)
