"""PA001 render-source-invalid."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, schemas
from usdrender_lint.api.resolve import (
    authored_targets,
    is_usable,
    prim_values,
    typed_target_problem,
)

from ._default_value import _value_lost_elsewhere


def _intended_absolute_settings(owner: Usd.Prim, target: Sdf.Path) -> Sdf.Path | None:
    """``/suffix`` when ``target`` is the owner's path + suffix and ``/suffix``
    is a usable RenderSettings: Sdf anchored a relative ``<suffix>`` to the
    owning prim (catalog, Ambiguous semantics 11)."""
    owner_path = owner.GetPath()
    if target == owner_path or not target.HasPrefix(owner_path) or not target.IsPrimPath():
        return None
    intended = Sdf.Path.absoluteRootPath.AppendPath(target.MakeRelativePath(owner_path))
    prim = owner.GetStage().GetPrimAtPath(intended)
    return intended if prim and is_usable(prim) and prim.IsA(schemas.RenderSettings) else None


def _replace_target(rel_path: Sdf.Path, old: Sdf.Path, new: Sdf.Path):
    def apply(stage: Usd.Stage) -> None:
        rel = stage.GetRelationshipAtPath(rel_path)
        rel.SetTargets([new if t == old else t for t in rel.GetTargets()])

    return apply


class RenderSourceInvalid(Rule):
    """A RenderPass without a fileName has no valid RenderSettings renderSource.

    ## What it does
    For a RenderPass with no authored, non-empty `fileName`, reports a
    `renderSource` relationship with no forwarded target, and each forwarded
    target that is not a prim path, has no prim, is inactive, `over`-only or
    abstract, or is not a RenderSettings. With `fileName` authored the target
    may name an object in that external file (e.g. a Nuke write node) and is
    not checked. A relative target such as `<Render/PrimarySettings>` is
    anchored by Sdf to the pass itself, so it usually dangles; the message
    says so.

    ## Why is this bad?
    *"If fileName is not present, the source is assumed to be a RenderSettings
    prim present in the current Usd stage."* (`pxr/usd/usdRender/schema.usda`,
    RenderPass `renderSource`). A pass with no stage source cannot be rendered.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "PrimarySettings"
        {
        }

        def Scope "Passes"
        {
            def RenderPass "beauty"
            {
                uniform token passType = "prman"
                rel renderSource = <Render/PrimarySettings>
            }
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "PrimarySettings"
        {
        }

        def Scope "Passes"
        {
            def RenderPass "beauty"
            {
                uniform token passType = "prman"
                rel renderSource = </Render/PrimarySettings>
            }
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when a dangling target is the pass's own path plus a
    suffix and `/suffix` is a RenderSettings (the relative-path mistake above),
    the fix rewrites that target to `/suffix`. Otherwise there is no fix.
    """

    code = "PA001"
    name = "render-source-invalid"
    severity = Severity.ERROR
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = (schemas.RenderPass,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        # Read by name: a schema object costs ~1.2 us a pass and is not needed.
        values = prim_values(prim)
        if _value_lost_elsewhere(values, "fileName"):
            return  # A fileName was meant; SE016 or SE017 reports how it is lost.
        file_name = values.authored("fileName")
        if file_name is not None and file_name.authoredPath:
            return
        rel = values.relationship("renderSource")
        targets = values.targets("renderSource")
        if not targets:
            yield Diagnostic(
                message=f"RenderPass {prim.GetPath()} has neither a fileName nor a renderSource "
                "target; point renderSource at the RenderSettings prim this pass renders, "
                "or author fileName when the source lives in another file",
                at=rel if rel.HasAuthoredTargets() else prim,
            )
            return
        for target in targets:
            problem = typed_target_problem(target, schemas.RenderSettings, "a RenderSettings")
            if problem is None:
                continue
            intended = _intended_absolute_settings(prim, target.path)
            fix = None
            advice = "target a RenderSettings prim, or author fileName for an external source"
            if intended is not None:
                relative = target.path.MakeRelativePath(prim.GetPath())
                advice = (
                    f"it looks like the relative path <{relative}>, which Sdf anchors to the "
                    f"pass; write the absolute path <{intended}>"
                )
                if target.path in authored_targets(rel):
                    fix = Fix(
                        description=f"retarget renderSource to <{intended}>",
                        safe=True,
                        apply=_replace_target(rel.GetPath(), target.path, intended),
                    )
            yield Diagnostic(
                message=f"renderSource target <{target.path}> {problem}; {advice}", at=rel, fix=fix
            )
