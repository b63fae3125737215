"""CA001 camera-unset."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity

from .._camera import usable_cameras


def _set_settings_camera(settings_path: Sdf.Path, camera_path: Sdf.Path):
    def apply(stage: Usd.Stage) -> None:
        from pxr import UsdRender  # the schema API, imported only when a fix runs (start-up)

        settings = UsdRender.SettingsBase(stage.GetPrimAtPath(settings_path))
        settings.CreateCameraRel().SetTargets([camera_path])

    return apply


class CameraUnset(Rule):
    """A RenderProduct of a RenderSettings has no camera at all.

    ## What it does
    For each (RenderSettings, usable product of its `products`) pair, reports
    when the effective camera is empty: the product's `camera` has no
    forwarded target and neither has the settings' `camera`. An authored empty
    product relationship (`rel camera = []`) does not clear the settings
    camera, so it is not a finding when the settings has one. Since catalog
    Revision 2 (R2-2) a RenderSettings with no usable products is never
    reported: nothing is dropped, and the application supplies the camera
    (usdview, Kit viewports, RTX Remix's settings container).

    ## Why is this bad?
    *"This relationship specifies the primary camera to use for a render. The
    relationship must target a Camera."* (`RenderSettings.md`). With no camera
    `UsdRenderComputeSpec` posts *"Could not find camera <> for the render
    product"* inside its loop over the products and drops that product from
    the render (`pxr/usd/usdRender/spec.cpp`); that loop is the only place it
    reports a missing camera (catalog R2-2). A renderer profile may say what
    its renderer does instead (`karma`: husk renders through a camera it
    finds on the stage, which need not be the shot's, or fails), and the
    finding then says that.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel products = </Render/Beauty>
        }

        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Camera "cam"
        {
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/cam>
            rel products = </Render/Beauty>
        }

        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
        }
    }
    ```

    ## Fix safety
    Unsafe: when the stage holds exactly one usable Camera, the fix targets it
    from the RenderSettings' `camera`. It picks a camera for you, so review it.
    """

    code = "CA001"
    name = "camera-unset"
    severity = Severity.ERROR
    partial_composition = True
    fix_safety = "unsafe"

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for config in ctx.configurations:
            # R2-2: only a (settings, product) pair loses a product; a settings
            # alone gets its camera from the application. A product rendered
            # on its own always has a camera target (R2-4).
            if config.settings is None or config.product is None:
                continue
            if config.camera_target is not None:
                continue
            settings_path = config.settings.GetPath()
            fix = None
            cameras = usable_cameras(ctx)
            if len(cameras) == 1:
                camera_path = cameras[0].GetPath()
                fix = Fix(
                    description=f"target the stage's only Camera <{camera_path}> from "
                    f"<{settings_path}>",
                    safe=False,
                    apply=_set_settings_camera(settings_path, camera_path),
                )
            # What happens then is the renderer's: the profile may say (husk
            # picks a camera of its own instead of dropping the product).
            behaviour = ctx.behaviour(self.code, config)
            consequence = (
                behaviour.what
                if behaviour is not None
                else 'UsdRenderComputeSpec drops the product ("Could not find camera")'
            )
            yield Diagnostic(
                message=f"RenderProduct <{config.product.GetPath()}> of <{settings_path}> has no "
                f"camera (neither the product's nor the settings' camera has a target); "
                f"{consequence}. Author rel camera = </path/to/Camera> on <{settings_path}> "
                "(or on the product)",
                at=config.settings,
                fix=fix,
            )
