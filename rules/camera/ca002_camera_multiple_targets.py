"""CA002 camera-multiple-targets."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf

from usdrender_lint.api import Context, Diagnostic, Rule, Severity
from usdrender_lint.api.resolve import prim_values

from .._camera import config_owners


class CameraMultipleTargets(Rule):
    """A camera relationship of a render configuration has several targets.

    ## What it does
    Reports the `camera` relationship of a RenderSettings, or of a RenderProduct
    in its `products`, when it has more than one forwarded target. Since catalog
    Revision 2 (R2-4) this includes a product rendered on its own (no usable
    RenderSettings targets it and it authors its own camera, as ovrtx and Kit
    render products by prim path).

    ## Why is this bad?
    The relationship names *"the primary camera"*, singular
    (`RenderSettings.md`). `UsdRenderComputeSpec` keeps only the first target
    (`pd->cameraPath = targets[0]`, `pxr/usd/usdRender/spec.cpp`), so the others
    are silently ignored and which one wins depends on list-op composition
    order. Stereo renders use one product per eye.

    ## Example
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Camera "cam_left"
        {
        }

        def Camera "cam_right"
        {
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = [</World/cam_left>, </World/cam_right>]
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Camera "cam_left"
        {
        }

        def Camera "cam_right"
        {
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/cam_left>
            rel products = [</Render/Left>, </Render/Right>]
        }

        def RenderProduct "Left"
        {
            token productName = "left.exr"
        }

        def RenderProduct "Right"
        {
            rel camera = </World/cam_right>
            token productName = "right.exr"
        }
    }
    ```

    ## Fix safety
    No automatic fix: only the author knows which camera is meant.
    """

    code = "CA002"
    name = "camera-multiple-targets"
    severity = Severity.WARNING
    partial_composition = True

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        seen: set[Sdf.Path] = set()
        for config in ctx.configurations:
            for owner in config_owners(config):
                values = prim_values(owner)
                targets = values.forwarded("camera")
                if len(targets) < 2:
                    continue
                rel = values.relationship("camera")
                if rel.GetPath() in seen:
                    continue
                seen.add(rel.GetPath())
                listed = ", ".join(f"<{t}>" for t in targets)
                yield Diagnostic(
                    message=f"camera has {len(targets)} targets ({listed}); renderers use only the "
                    f"first, <{targets[0]}>, and ignore the rest. Keep one camera here "
                    "(use one RenderProduct per camera for stereo)",
                    at=rel,
                )
