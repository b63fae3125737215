"""``omniverse``: Omniverse RTX (Kit viewports, Isaac Sim sensors, ovrtx)."""

from __future__ import annotations

from .model import Accepted, Profile, RuleChange

OVRTX_CONFIG_DOC = (
    "ovrtx docs, Sensor Configuration "
    "(https://nvidia-omniverse.github.io/ovrtx/sensors/configuration.html)"
)
OVRTX_RADAR_DOC = (
    "ovrtx docs, Radar Sensors (https://nvidia-omniverse.github.io/ovrtx/sensors/radar.html)"
)
ISAAC_LIDAR_DOC = (
    "Isaac Sim docs, RTX Lidar Sensor "
    "(https://docs.isaacsim.omniverse.nvidia.com/latest/sensors/isaacsim_sensors_rtx_lidar.html)"
)
ISAAC_RADAR_DOC = (
    "Isaac Sim docs, RTX Radar Sensor "
    "(https://docs.isaacsim.omniverse.nvidia.com/latest/sensors/isaacsim_sensors_rtx_radar.html)"
)
ISAAC_ACOUSTIC_DOC = (
    "Isaac Sim docs, RTX Acoustic Sensor "
    "(https://docs.isaacsim.omniverse.nvidia.com/latest/sensors/isaacsim_sensors_rtx_acoustic.html)"
)
#: The acoustic sensor's own schema (formerly "Ultrasonic"): OmniAcoustic.
ACOUSTIC_SCHEMA_DOC = (
    "Omniverse Kit docs, omni.sensors.nv.acoustic, Omniverse Acoustic Extension "
    "(https://docs.omniverse.nvidia.com/kit/docs/omni.sensors.nv.acoustic/3.0.0/"
    "acoustic_extension.html)"
)
REMIX_PERSP_DOC = (
    "Omniverse Kit docs, RTX Remix lightspeed.event.capture_persp_to_persp "
    "(https://docs.omniverse.nvidia.com/kit/docs/rtx_remix/latest/source/extensions/"
    "lightspeed.event.capture_persp_to_persp/docs/README.html)"
)
SENSOR_SCHEMA_DOC = (
    "Omniverse Kit docs, omni.usd.schema.omni_sensors "
    "(https://docs.omniverse.nvidia.com/kit/docs/omni.usd.schema.omni_sensors/latest/index.html)"
)
#: The 107.x schema extension, whose typed schemas are OmniSensor, OmniRadar,
#: OmniLidar, OmniUltrasonic and OmniGeneralSensor; its 110.x pages list
#: OmniAcoustic in OmniUltrasonic's place.
SENSOR_SCHEMA_107_DOC = (
    "Omniverse Kit docs, omni.usd.schema.omni_sensors 107.3.0, Typed Schema: OmniUltrasonic "
    "(https://docs.omniverse.nvidia.com/kit/docs/omni.usd.schema.omni_sensors/107.3.0/index.html)"
)

KIT_VIEWPORT_CHANGELOG = (
    "Omniverse Kit docs, omni.kit.widget.viewport CHANGELOG 105.1.2 (a stage 'with implicit "
    "camera saved to' it) "
    "(https://docs.omniverse.nvidia.com/kit/docs/omni.kit.widget.viewport/106.0.2/CHANGELOG.html)"
)
#: Kit's own render-settings schemas, which it applies to its render prims.
RTX_SETTINGS_SCHEMA_DOC = (
    "Omniverse Kit docs, omni.usd.schema.render_settings.rtx, Settings "
    "(https://docs.omniverse.nvidia.com/kit/docs/omni.usd.schema.render_settings.rtx/1.0.0/"
    "SETTINGS.html)"
)
#: Which camera attributes RTX ignores (CA006 is kept: the apertures are read).
KIT_CAMERAS_DOC = (
    "Omniverse docs, Materials and Rendering, Cameras "
    "(https://docs.omniverse.nvidia.com/app_view/prod_materials-and-rendering/cameras.html)"
)
#: NVIDIA's Kit extensions record the viewport's bound camera in the root
#: layer's customLayerData (cameraSettings:boundCamera = "/OmniverseKit_Persp").
KIT_LAYER_DATA_SRC = (
    "NVIDIA-Omniverse/PhysX, omni.physx demos (set_initial_camera writes the root layer's "
    'customLayerData cameraSettings.boundCamera = "/OmniverseKit_Persp" for Kit\'s viewport)'
)

#: Where Kit keeps the render products of its viewports: a stage Kit saved,
#: in NVIDIA's own repository, holds its viewport's product there.
KIT_SCOPE_SRC = (
    "NVIDIA-Omniverse/PhysX ovphysx/tests/data/links_chain_sample.usda (saved by Kit: "
    "RenderProduct /Render/OmniverseKit/HydraTextures/omni_kit_widget_viewport_ViewportTexture_0)"
)

_SESSION_CAMERA = (
    "Kit creates its viewport cameras /OmniverseKit_Persp, _Front, _Top and _Right in the "
    "session layer of every stage it opens, so a saved viewport product targets a camera the "
    "file does not hold, or holds only as an `over` (typeless or `over Camera`) carrying the "
    "viewport's edits, which composes onto the session layer's camera"
)

# CA006 (aspect mismatch with an implicit conform policy) is kept, not
# changed: KIT_CAMERAS_DOC says RTX ignores the aperture offsets, shutter and
# stereo role but reads both apertures, and no public source says how RTX
# conforms a mismatch or whether it reads aspectRatioConformPolicy. CA008,
# which reads only the shutter, is off for the same page's reason.
OMNIVERSE = Profile(
    name="omniverse",
    description="Omniverse RTX (Kit viewports, Isaac Sim and ovrtx sensors): render products "
    "are GPU buffers addressed by prim path; RTX sensors are OmniLidar / OmniRadar / "
    "OmniAcoustic prims (OV rules).",
    family="OV",
    # Kit's render settings schemas name their properties omni:rtx:*
    # (RTX_SETTINGS_SCHEMA_DOC); the omni:kit:* properties Kit writes
    # (centerOfInterest, cameraLock) sit on cameras, which are no evidence.
    namespaces=("omni:rtx:",),
    api_schemas=("OmniRtx*",),
    scopes=("/Render/OmniverseKit/",),
    evidence_sources=(RTX_SETTINGS_SCHEMA_DOC, KIT_SCOPE_SRC),
    layer_data=(
        Accepted(
            name="cameraSettings:boundCamera",
            why="Kit keeps the camera its viewport is bound to in the root layer's "
            "customLayerData, dictionary cameraSettings, key boundCamera",
            source=KIT_LAYER_DATA_SRC,
        ),
    ),
    changes=(
        RuleChange(
            code="PR001",
            severity=None,
            why="an RTX render product is a buffer the application reads by the product's prim "
            "path (ovrtx: renderer.step(render_products={path}); Kit: a Hydra texture); "
            "it writes no file, so it needs no productName",
            source=OVRTX_CONFIG_DOC,
        ),
        RuleChange(
            code="CA008",
            severity=None,
            why="RTX ignores the camera's shutter:open and shutter:close (Kit lets them be "
            "set as the schema says, but RTX rendering does not read them), so an inverted "
            "interval does not black out an RTX image",
            source=KIT_CAMERAS_DOC,
        ),
    ),
    camera_types=(
        Accepted(
            name="OmniLidar",
            why="RTX lidars are OmniLidar prims that a render product's camera targets",
            source=ISAAC_LIDAR_DOC,
        ),
        Accepted(
            name="OmniRadar",
            why="RTX radars are OmniRadar prims that a render product's camera targets",
            source=ISAAC_RADAR_DOC,
        ),
        Accepted(
            name="OmniAcoustic",
            why="RTX acoustic (formerly ultrasonic) sensors are OmniAcoustic prims that a "
            "render product is attached to; the RTXSensor renderer writes their results to "
            "its GenericModelOutput AOV",
            source=ISAAC_ACOUSTIC_DOC,
        ),
    ),
    runtime_cameras=tuple(
        Accepted(
            name=f"/OmniverseKit_{view}",
            why=_SESSION_CAMERA,
            source=f"{REMIX_PERSP_DOC}; {KIT_VIEWPORT_CHANGELOG}",
        )
        for view in ("Persp", "Front", "Top", "Right")
    ),
    prim_types=tuple(
        Accepted(
            name=type_name,
            why="an RTX sensor type of omni.usd.schema.omni_sensors, registered where Kit or "
            "ovrtx runs",
            source=SENSOR_SCHEMA_DOC,
        )
        for type_name in (
            "OmniSensor",
            "OmniLidar",
            "OmniRadar",
            "OmniGeneralSensor",
        )
    )
    + (
        Accepted(
            name="OmniUltrasonic",
            why="the RTX ultrasonic sensor type of omni.usd.schema.omni_sensors up to 107.x "
            "(110.x defines OmniAcoustic in its place), registered where such a Kit or Isaac "
            "Sim runs",
            source=SENSOR_SCHEMA_107_DOC,
        ),
        Accepted(
            name="OmniAcoustic",
            why="the RTX acoustic sensor type, registered where Kit's acoustic sensor "
            "extension runs",
            source=ACOUSTIC_SCHEMA_DOC,
        ),
    ),
)
