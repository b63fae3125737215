"""``karma``: Houdini's Karma (CPU and XPU), rendered by husk."""

from __future__ import annotations

from ..model import Severity
from .model import Behaviour, Profile, RuleChange

#: The husk reference page (Houdini 21.0, "Stand-alone utilities: husk").
HUSK_DOC = "Houdini docs, husk (https://www.sidefx.com/docs/houdini/ref/utils/husk.html)"
#: The Karma Render Settings LOP page, parameter "Output Picture".
KARMA_SETTINGS_DOC = (
    "Houdini docs, Karma Render Settings LOP, Output Picture "
    "(https://www.sidefx.com/docs/houdini/nodes/lop/karmarendersettings.html)"
)

#: The Karma rendering properties page: the render properties Karma reads,
#: which Houdini's Karma LOPs author as karma:* properties.
KARMA_PROPERTIES_DOC = (
    "Houdini docs, Karma rendering properties "
    "(https://www.sidefx.com/docs/houdini/props/karma.html)"
)
#: SideFX publishes no page on the Karma* API schemas, so the citation is
#: stages Houdini wrote, in a public repository: with Houdini's own
#: Houdini*API schemas they apply KarmaRenderSettingsAPI to the RenderSettings,
#: KarmaAOVSettingsAPI to a RenderVar and KarmaCameraSettingsAPI to the camera.
KARMA_API_SCHEMAS_SRC = (
    "Autodesk/arnold-usd testsuite/test_2434.1/data/test.usda (RenderSettings with "
    "apiSchemas KarmaRenderSettingsAPI), testsuite/test_0232/data/test.usda (RenderVar with "
    "KarmaAOVSettingsAPI) and testsuite/test_0233/data/test.usda (Camera with "
    "KarmaCameraSettingsAPI beside HoudiniCameraPlateAPI): stages Houdini wrote"
)

#: husk's reading of the render settings (Houdini's USD library, published by
#: SideFX under the Apache licence).
HUSK_SETTINGS_SRC = "sideeffects/HoudiniUsdBridge src/houdini/lib/H_USD/HUSD/XUSD_RenderSettings.C"

KARMA = Profile(
    name="karma",
    description="Houdini's Karma CPU / XPU through husk: the schema plus husk's "
    "output conventions (KA rules).",
    family="KA",
    namespaces=("karma:",),
    api_schemas=("Karma*",),
    evidence_sources=(KARMA_PROPERTIES_DOC, KARMA_API_SCHEMAS_SRC),
    changes=(
        RuleChange(
            code="SE017",
            severity=Severity.INFO,
            why="husk reads the render settings, products and vars at the frame it renders "
            "(again at each frame when it renders several, the productName too), so time "
            "samples on their uniform attributes are rendered, not ignored; only tools that "
            "read the default time, as UsdRenderComputeSpec does, get the fallback",
            source=f"{HUSK_SETTINGS_SRC} (XUSD_RenderSettings::loadFromPrim and "
            "XUSD_RenderProduct::updateSettings read at ctx.evalTime(); updateSettings takes "
            "a time-varying productName frame by frame)",
        ),
    ),
    behaviours=(
        Behaviour(
            code="SE017",
            what="husk reads it at the frame it renders and follows the samples",
            source=f"{HUSK_SETTINGS_SRC} (XUSD_RenderSettings::loadFromPrim, "
            "XUSD_RenderProduct::updateSettings)",
        ),
        Behaviour(
            code="CA001",
            what="husk does not drop the product: it renders it through a camera it finds on "
            'the stage (warning "No camera in render settings, defaulting to ..."), '
            "which need not be the shot's camera, and fails the render when the stage holds "
            "no camera (older releases also when it holds several)",
            source=f"{HUSK_SETTINGS_SRC} (XUSD_RenderSettings::loadFromOptions: findCameras "
            "when neither the settings nor a product names a camera)",
        ),
    ),
)
