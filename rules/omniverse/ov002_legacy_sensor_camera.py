"""OV002 rtx-legacy-sensor-camera."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import authored_value, forwarded_targets

#: The Camera attribute that made a Camera prim an RTX sensor before Isaac Sim 5.0.
PLUGIN_ATTR = "sensorModelPluginName"


class LegacySensorCamera(Rule):
    """A render product renders an RTX sensor built on a Camera prim.

    ## What it does
    Under the `omniverse` profile, reports a RenderProduct whose `camera`
    targets a Camera prim with an authored, non-empty `sensorModelPluginName`:
    the pre-5.0 way to make a Camera an RTX lidar or radar.

    ## Why is this bad?
    *"In Isaac Sim 4.5 and earlier, RTX sensors were based on Camera prims. If
    the Camera prim's sensorModelPluginName attribute was set to
    omni.sensors.nv.lidar.lidar_core.plugin, then the Camera prim was used to
    render the Lidar ... Support for Camera prims as RTX Lidars was deprecated
    in Isaac Sim 5.0."* (Isaac Sim docs, RTX Lidar Sensor; likewise RTX Radar
    Sensor). Current renderers expect an `OmniLidar` / `OmniRadar` prim; the old
    camera renders as a plain camera or not at all.

    ## Example
    ```usda
    #usda 1.0

    def Camera "Lidar"
    {
        string sensorModelPluginName = "omni.sensors.nv.lidar.lidar_core.plugin"
    }

    def Scope "Render"
    {
        def RenderProduct "LidarProduct"
        {
            rel camera = </Lidar>
            token omni:rtx:rendermode = "RaytracedLighting"
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def OmniLidar "Lidar"
    {
    }

    def Scope "Render"
    {
        def RenderProduct "LidarProduct"
        {
            rel camera = </Lidar>
            token omni:rtx:rendermode = "RaytracedLighting"
        }
    }
    ```

    ## Fix safety
    No automatic fix: converting the sensor's JSON profile to OmniLidar
    attributes is Isaac Sim's conversion tool's job.
    """

    code = "OV002"
    name = "rtx-legacy-sensor-camera"
    severity = Severity.WARNING
    partial_composition = True
    profile = "omniverse"
    prim_types = (schemas.RenderProduct,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        cameras = forwarded_targets(prim.GetRelationship("camera"))
        camera = ctx.stage.GetPrimAtPath(cameras[0]) if cameras else None
        if not camera or not camera.IsA(schemas.Camera):
            return
        plugin = authored_value(camera.GetAttribute(PLUGIN_ATTR))
        if not plugin:
            return
        yield Diagnostic(
            message=f"RenderProduct {prim.GetPath()} renders the Camera <{camera.GetPath()}> as "
            f"an RTX sensor ({PLUGIN_ATTR} = {str(plugin)!r}), which Isaac Sim deprecated in "
            "5.0; convert it to an OmniLidar or OmniRadar prim",
            at=prim.GetRelationship("camera"),
        )
