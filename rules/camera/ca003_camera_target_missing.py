"""CA003 camera-target-missing."""

from __future__ import annotations

from collections.abc import Iterator

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import RenderConfiguration, prim_values


def _camera_rel_label(config: RenderConfiguration) -> str:
    return str(config.camera_relationship.GetPath())


class CameraTargetMissing(Rule):
    """The render camera target does not exist, or is a Camera that is not usable.

    ## What it does
    For each render configuration (a RenderSettings with each of its products,
    and, since catalog Revision 2 (R2-4), each product rendered on its own: no
    usable RenderSettings targets it and it authors its own camera, as ovrtx
    and Kit render products by prim path), takes the effective camera (the
    product's first forwarded `camera` target if it has one, else the
    settings') and reports it when no prim exists at that path on the composed
    stage, or when the prim is a Camera that is inactive, only an `over`, or
    abstract (a `class`). Relative targets are anchored by Sdf to the owning
    prim before the check.

    ## Why is this bad?
    *"This relationship specifies the primary camera to use for a render. The
    relationship must target a Camera."* (`RenderSettings.md`).
    `UsdRenderComputeSpec` drops the product with *"Could not find camera"*
    (`pxr/usd/usdRender/spec.cpp`), and Hydra's default traversal never sees
    an inactive, `over`-only or abstract camera.

    ## Example
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Camera "shotCam"
        {
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/main_cam>
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Camera "shotCam"
        {
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/shotCam>
        }
    }
    ```

    ## Fix safety
    No automatic fix: only the author knows which camera was meant.

    ## Profiles
    A renderer profile may name cameras its application creates at run time
    (the `omniverse` profile: Kit's `/OmniverseKit_Persp`, `_Front`, `_Top`,
    `_Right`, made in the session layer); a target at such a path is no
    finding under that profile when the stage holds nothing there, or only
    `over`s (typeless or `over Camera`, in any layer: a stage saved from Kit
    keeps the viewport's edits as such an `over`, which composes onto the
    session layer's camera). A `def` there, or a deactivated `over`, is
    still judged.

    The message of a Camera that is not defined because an ancestor is only
    an `over` names that ancestor.
    """

    code = "CA003"
    name = "camera-target-missing"
    severity = Severity.ERROR
    partial_composition = True

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        # The camera relationships reported, by identity (a prim's values hold
        # one handle per name for the lint): the products of a settings that
        # inherit its camera share its relationship, target and finding, which
        # is made once, not once per product (the engine kept one of them).
        reported: set[int] = set()
        for config in ctx.configurations:
            target = config.camera_target
            if target is None:
                continue
            if target.is_missing:
                if ctx.runtime_camera(config) is not None:
                    continue  # the renderer's application creates it at run time (R2-5)
                reason = target.problem
            elif (
                target.prim is not None
                and not target.ok
                and prim_values(target.prim).is_a(schemas.Camera)
            ):
                if ctx.runtime_camera(config) is not None:
                    continue  # an `over Camera` composing onto the application's camera
                reason = f"is a Camera but {target.problem}"
            else:
                continue
            rel = config.camera_relationship
            if id(rel) in reported:
                continue
            reported.add(id(rel))
            yield Diagnostic(
                message=f"camera target <{target.path}> {reason}; point "
                f"{_camera_rel_label(config)} at a defined, active Camera prim",
                at=rel,
            )
