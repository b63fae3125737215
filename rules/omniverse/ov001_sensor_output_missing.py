"""OV001 rtx-sensor-output-missing."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import authored_value, forwarded_targets, resolve_targets

#: The RenderVars each RTX sensor type writes: GenericModelOutput (Isaac Sim's
#: RTX lidar, radar and acoustic sensors), PointCloud (ovrtx's lidar and
#: radar) and SignalWays (ovrtx's acoustic sensor).
SENSOR_OUTPUTS = {
    "OmniLidar": ("GenericModelOutput", "PointCloud"),
    "OmniRadar": ("GenericModelOutput", "PointCloud"),
    "OmniAcoustic": ("GenericModelOutput", "SignalWays"),
}


class SensorOutputMissing(Rule):
    """An RTX lidar, radar or acoustic product requests no sensor output.

    ## What it does
    Under the `omniverse` profile, reports a RenderProduct whose `camera`
    targets an `OmniLidar` or `OmniRadar` prim when none of its `orderedVars`
    is a RenderVar with `sourceName` `GenericModelOutput` or `PointCloud`, or
    an `OmniAcoustic` prim when none is `GenericModelOutput` or `SignalWays`.

    ## Why is this bad?
    *"After attaching a render product to the OmniLidar prim, and setting the
    GenericModelOutput AOV on the render product, the RTXSensor renderer will
    write Lidar render results to the AOV."* (Isaac Sim docs, RTX Lidar Sensor;
    the same for OmniRadar, RTX Radar Sensor, and OmniAcoustic, RTX Acoustic
    Sensor); ovrtx needs *"a RenderProduct whose PointCloud RenderVar requests
    the detection channels"* (ovrtx docs, Radar Sensors) and, for an acoustic
    sensor, *"a RenderProduct whose SignalWays RenderVar delivers the sensor's
    output"* (ovrtx docs, Acoustic Sensors). Without one the sensor is
    simulated for nothing: the application reads no returns.

    ## Example
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
            rel orderedVars = </Render/LidarProduct/LdrColor>
            token omni:rtx:rendermode = "RaytracedLighting"

            def RenderVar "LdrColor"
            {
                string sourceName = "LdrColor"
            }
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
            rel orderedVars = </Render/LidarProduct/GenericModelOutput>
            token omni:rtx:rendermode = "RaytracedLighting"

            def RenderVar "GenericModelOutput"
            {
                string sourceName = "GenericModelOutput"
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: the output a sensor pipeline reads (GenericModelOutput,
    PointCloud or SignalWays, and its channels) is the application's choice.
    """

    code = "OV001"
    name = "rtx-sensor-output-missing"
    severity = Severity.WARNING
    partial_composition = True
    profile = "omniverse"
    prim_types = (schemas.RenderProduct,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        cameras = forwarded_targets(prim.GetRelationship("camera"))
        sensor = ctx.stage.GetPrimAtPath(cameras[0]) if cameras else None
        outputs = SENSOR_OUTPUTS.get(sensor.GetTypeName()) if sensor else None
        if not sensor or not outputs:
            return
        for target in resolve_targets(prim.GetRelationship("orderedVars")):
            if target.ok and target.prim is not None and target.prim.IsA(schemas.RenderVar):
                source = authored_value(target.prim.GetAttribute("sourceName"))
                if str(source or "") in outputs:
                    return
        yield Diagnostic(
            message=f"RenderProduct {prim.GetPath()} renders the {sensor.GetTypeName()} "
            f"<{sensor.GetPath()}> but none of its orderedVars has sourceName "
            f"{' or '.join(outputs)}, so the sensor's returns are never written; "
            "add a RenderVar for them",
            at=prim,
        )
