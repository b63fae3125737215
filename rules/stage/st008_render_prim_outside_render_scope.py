"""ST008 render-prim-outside-render-scope."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity
from usdrender_lint.api.resolve import prim_values

from ._render_prims import RENDER_SCHEMAS, RENDER_SCOPE, is_render_type
from ._settings_path import RENDER_SETTINGS_PATH_KEY


def _is_locally_authored(prim: Usd.Prim) -> bool:
    """Every opinion on the prim sits at its own path in the stage's layer stack."""
    stage = prim.GetStage()
    return all(
        spec.path == prim.GetPath() and stage.HasLocalLayer(spec.layer)
        for spec in prim.GetPrimStack()
    )


def _move_under_render_scope(source: Sdf.Path, destination: Sdf.Path):
    def apply(stage: Usd.Stage) -> None:
        if not stage.GetPrimAtPath(RENDER_SCOPE):
            from pxr import UsdGeom  # the schema API, imported only when a fix runs (start-up)

            UsdGeom.Scope.Define(stage, RENDER_SCOPE)
        editor = Usd.NamespaceEditor(stage)
        if not (editor.MovePrimAtPath(source, destination) and editor.ApplyEdits()):
            raise RuntimeError(f"could not move <{source}> to <{destination}>")
        # The namespace editor rewrote the targets in the layer stack, but not the
        # stage metadata: left naming the old path, it made ST005's error.
        _follow_settings_path(stage.GetRootLayer(), source, destination)

    return apply


def _follow_settings_path(layer: Sdf.Layer, source: Sdf.Path, destination: Sdf.Path) -> None:
    """Rewrite ``layer``'s renderSettingsPrimPath that names ``source`` or a prim below it."""
    root = layer.pseudoRoot
    if not root.HasInfo(RENDER_SETTINGS_PATH_KEY):
        return
    named = str(root.GetInfo(RENDER_SETTINGS_PATH_KEY))
    if not Sdf.Path.IsValidPathString(named) or not Sdf.Path(named).HasPrefix(source):
        return
    root.SetInfo(RENDER_SETTINGS_PATH_KEY, str(Sdf.Path(named).ReplacePrefix(source, destination)))


class RenderPrimOutsideRenderScope(Rule):
    """A render prim lives outside /Render.

    ## What it does
    Reports a usable RenderSettings, RenderProduct, RenderVar or RenderPass
    whose path is not under `/Render`.

    ## Why is this bad?
    *"UsdRender follows a naming convention that all render settings in the
    scene must live under the path `</Render>`"* so that
    `UsdStage::OpenMasked()` can compose just the render data
    (`pxr/usd/usdRender/overview.dox`); the user guide softens it to a best
    practice (`docs/user_guides/render_user_guide.rst`), hence info.

    ## Example
    ```usda
    #usda 1.0

    def RenderSettings "Settings"
    {
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
        }
    }
    ```

    ## Fix safety
    Unsafe: the fix moves the prim under `/Render` with `Usd.NamespaceEditor`
    (creating a `/Render` Scope when needed), offered only for the outermost
    render prim and when `/Render/<name>` is free. The editor rewrites
    relationship targets of the old path in the stage's layer stack, and the
    fix rewrites the root layer's `renderSettingsPrimPath` when it names the
    prim; other files that reference the old path are not updated.
    """

    code = "ST008"
    name = "render-prim-outside-render-scope"
    severity = Severity.INFO
    partial_composition = True
    fix_safety = "unsafe"
    prim_types = RENDER_SCHEMAS

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        path = prim_values(prim).path
        if path.HasPrefix(RENDER_SCOPE):
            return
        destination = RENDER_SCOPE.AppendChild(prim.GetName())
        fix = None
        # A nested render prim moves with its render-prim parent; a prim that
        # a reference or other arc brings in cannot be moved by editing this stage.
        if (
            not is_render_type(prim.GetParent())
            and not ctx.stage.GetPrimAtPath(destination)
            and _is_locally_authored(prim)
        ):
            fix = Fix(
                description=f"move to <{destination}> (other files referencing it are not updated)",
                safe=False,
                apply=_move_under_render_scope(path, destination),
            )
        yield Diagnostic(
            message=f"{prim.GetTypeName()} <{path}> is outside </Render>; the usdRender "
            "convention keeps render prims under </Render> so that masked stages compose "
            "them alone. Move it under </Render>",
            at=prim,
            fix=fix,
        )
