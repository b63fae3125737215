"""``renderman``: RenderMan through hdPrman (OpenUSD's third_party/renderman-*)."""

from __future__ import annotations

from .model import Accepted, Profile

USD_RI_PXR = "OpenUSD third_party/renderman-26/plugin/usdRiPxr/schema.usda"

RENDERMAN = Profile(
    name="renderman",
    description="RenderMan through hdPrman: the schema plus hdPrman's render terminals "
    "(RM rules) and RenderMan's own prim types.",
    family="RM",
    namespaces=("ri:", "outputs:ri:"),
    api_schemas=("Pxr*",),
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
