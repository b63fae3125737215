"""CA004 camera-target-not-camera."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, schemas
from usdrender_lint.api.resolve import describe_prim_type, is_usable, prim_values


def _single_camera_descendant(prim: Usd.Prim) -> Usd.Prim | None:
    cameras = [
        p for p in Usd.PrimRange(prim) if p != prim and p.IsA(schemas.Camera) and is_usable(p)
    ]
    return cameras[0] if len(cameras) == 1 else None


def _retarget(rel_path: Sdf.Path, new_target: Sdf.Path):
    def apply(stage: Usd.Stage) -> None:
        rel = stage.GetRelationshipAtPath(rel_path)
        targets = list(rel.GetTargets())
        rel.SetTargets([new_target, *targets[1:]])

    return apply


class CameraTargetNotCamera(Rule):
    """The render camera target is not a Camera prim.

    ## What it does
    For each render configuration (since catalog Revision 2 (R2-4) also each
    product rendered on its own: no usable RenderSettings targets it and it
    authors its own camera), reports the effective camera target when it
    resolves to a prim that is not a `schemas.Camera` (an Xform camera rig, a
    Scope, a typeless `def`) or to a property path such as
    `</World/cam.focalLength>`.

    ## Why is this bad?
    *"This relationship specifies the primary camera to use for a render. The
    relationship must target a Camera."* (`RenderSettings.md`); *"It must
    target a UsdGeomCamera."* (`pxr/usd/usdRender/schema.usda`). spec.cpp reads
    the target as `UsdGeomCamera`, and anything else drops the product with
    *"Could not find camera"*.

    ## Example
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Xform "camRig"
        {
            def Camera "cam"
            {
            }
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/camRig>
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Xform "camRig"
        {
            def Camera "cam"
            {
            }
        }
    }

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel camera = </World/camRig/cam>
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when the target prim has exactly one Camera descendant
    (the rig case) the fix retargets to it; a property path is retargeted to its
    owning prim when that prim is a Camera. Otherwise there is no fix.

    ## Profiles
    A renderer profile may accept its own camera-like prim types (the
    `omniverse` profile: `OmniLidar`, `OmniRadar`); a target of such a type is
    then no finding, and a finding names the types the profile accepts. A
    typeless `over` at the path of a camera the profile's application creates
    at run time (Kit's `/OmniverseKit_Persp`, ...) composes onto that camera
    and is no finding either; a `def` of another type there still is.
    """

    code = "CA004"
    name = "camera-target-not-camera"
    severity = Severity.ERROR
    partial_composition = True
    fix_safety = "safe-conditional"

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        # As in CA003: the products of a settings that inherit its camera share
        # its relationship (one handle per prim and name in a lint), target and
        # finding, made once.
        reported: set[int] = set()
        for config in ctx.configurations:
            target = config.camera_target
            if target is None or target.is_missing:
                continue
            suggestion: Usd.Prim | None = None
            if target.path.IsPropertyPath():
                what = "a property, not a prim"
                owner = ctx.stage.GetPrimAtPath(target.path.GetPrimPath())
                if owner and owner.IsA(schemas.Camera) and is_usable(owner):
                    suggestion = owner
            elif target.prim is not None and not prim_values(target.prim).is_a(schemas.Camera):
                # (prim is None only when missing or a property path: both handled above)
                if ctx.runtime_camera(config) is not None:
                    continue  # a typeless `over` on the application's session camera (R2-5)
                camera_type = target.prim.GetTypeName()
                if ctx.profile_accepts(config.camera_relationship, "camera_type", camera_type):
                    continue  # a renderer's own sensor type (R2-5)
                what = describe_prim_type(target.prim)
                if target.problem:
                    what += f" that {target.problem}"
                suggestion = _single_camera_descendant(target.prim)
            else:
                continue
            # Looked up for a finding only: most configurations target a Camera.
            rel = config.camera_relationship
            if id(rel) in reported:
                continue
            reported.add(id(rel))
            others = ctx.accepted_names(rel, "camera_types")
            if others:
                what += f", not a Camera (nor {', '.join(others)}, which this profile accepts)"
            else:
                what += ", not a Camera"
            if suggestion is None:
                yield Diagnostic(
                    message=f"camera target <{target.path}> is {what}; point it at a Camera prim",
                    at=rel,
                )
                continue
            new_path = suggestion.GetPath()
            yield Diagnostic(
                message=f"camera target <{target.path}> is {what}; "
                f"target the Camera <{new_path}> instead",
                at=rel,
                fix=Fix(
                    description=f"retarget camera to <{new_path}>",
                    safe=True,
                    apply=_retarget(rel.GetPath(), new_path),
                ),
            )
