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
REMIX_PERSP_DOC = (
    "Omniverse Kit docs, RTX Remix lightspeed.event.capture_persp_to_persp "
    "(https://docs.omniverse.nvidia.com/kit/docs/rtx_remix/latest/source/extensions/"
    "lightspeed.event.capture_persp_to_persp/docs/README.html)"
)
SENSOR_SCHEMA_DOC = (
    "Omniverse Kit docs, omni.usd.schema.omni_sensors "
    "(https://docs.omniverse.nvidia.com/kit/docs/omni.usd.schema.omni_sensors/latest/index.html)"
)

_SESSION_CAMERA = (
    "Kit creates its viewport cameras /OmniverseKit_Persp, _Front, _Top and _Right in the "
    "session layer of every stage it opens, so a saved viewport product targets a camera the "
    "file does not hold"
)

OMNIVERSE = Profile(
    name="omniverse",
    description="Omniverse RTX (Kit viewports, Isaac Sim and ovrtx sensors): render products "
    "are GPU buffers addressed by prim path; RTX sensors are OmniLidar / OmniRadar prims "
    "(OV rules).",
    family="OV",
    namespaces=("omni:rtx:", "omni:kit:"),
    api_schemas=("OmniRtx*",),
    scopes=("/Render/OmniverseKit/",),
    changes=(
        RuleChange(
            code="PR001",
            severity=None,
            why="an RTX render product is a buffer the application reads by the product's prim "
            "path (ovrtx: renderer.step(render_products={path}); Kit: a Hydra texture); "
            "it writes no file, so it needs no productName",
            source=OVRTX_CONFIG_DOC,
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
    ),
    runtime_cameras=tuple(
        Accepted(name=f"/OmniverseKit_{view}", why=_SESSION_CAMERA, source=REMIX_PERSP_DOC)
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
            "OmniUltrasonic",
            "OmniGeneralSensor",
        )
    ),
)
