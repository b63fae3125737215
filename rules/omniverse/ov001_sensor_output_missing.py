"""OV001 rtx-sensor-output-missing."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import authored_value, forwarded_targets, resolve_targets

#: The RenderVars an RTX sensor writes: GenericModelOutput (Isaac Sim's RTX
#: lidar and radar) and PointCloud (ovrtx's lidar and radar).
SENSOR_OUTPUTS = ("GenericModelOutput", "PointCloud")
SENSOR_TYPES = ("OmniLidar", "OmniRadar")


class SensorOutputMissing(Rule):
    """An RTX lidar or radar product requests no sensor output.

    ## What it does
    Under the `omniverse` profile, reports a RenderProduct whose `camera`
    targets an `OmniLidar` or `OmniRadar` prim when none of its `orderedVars`
    is a RenderVar with `sourceName` `GenericModelOutput` or `PointCloud`.

    ## Why is this bad?
    *"After attaching a render product to the OmniLidar prim, and setting the
    GenericModelOutput AOV on the render product, the RTXSensor renderer will
    write Lidar render results to the AOV."* (Isaac Sim docs, RTX Lidar Sensor;
    the same for OmniRadar, RTX Radar Sensor); ovrtx needs *"a RenderProduct
    whose PointCloud RenderVar requests the detection channels"* (ovrtx docs,
    Radar Sensors). Without one the sensor is simulated for nothing: the
    application reads no returns.

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
    No automatic fix: the output a sensor pipeline reads (GenericModelOutput or
    PointCloud, and its channels) is the application's choice.
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
        if not sensor or sensor.GetTypeName() not in SENSOR_TYPES:
            return
        for target in resolve_targets(prim.GetRelationship("orderedVars")):
            if target.ok and target.prim is not None and target.prim.IsA(schemas.RenderVar):
                source = authored_value(target.prim.GetAttribute("sourceName"))
                if str(source or "") in SENSOR_OUTPUTS:
                    return
        yield Diagnostic(
            message=f"RenderProduct {prim.GetPath()} renders the {sensor.GetTypeName()} "
            f"<{sensor.GetPath()}> but none of its orderedVars has sourceName "
            f"{' or '.join(SENSOR_OUTPUTS)}, so the sensor's returns are never written; "
            "add a RenderVar for them",
            at=prim,
        )
