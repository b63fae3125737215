"""PR005 ordered-vars-invalid-target."""

from __future__ import annotations

from collections.abc import Callable, Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, schemas
from usdrender_lint.api.resolve import Target, authored_targets, describe_prim_type, prim_values

from .._aov import ordered_var_targets, product_render_vars


def _problem(target: Target) -> str | None:
    """Why an orderedVars target is not a usable RenderVar (None: it is one)."""
    if target.prim is None:
        return target.problem
    if not prim_values(target.prim).is_a(schemas.RenderVar):
        reason = f"is {describe_prim_type(target.prim)}, not a RenderVar"
        return f"{reason}, and {target.problem}" if target.problem else reason
    return f"is a RenderVar but {target.problem}" if target.problem else None


def _remove_target(rel_path: Sdf.Path, target: Sdf.Path) -> Callable[[Usd.Stage], None]:
    def apply(stage: Usd.Stage) -> None:
        stage.GetRelationshipAtPath(rel_path).RemoveTarget(target)

    return apply


class OrderedVarsInvalidTarget(Rule):
    """An orderedVars target is not a usable RenderVar.

    ## What it does
    Checks each forwarded `orderedVars` target of a usable RenderProduct and
    reports one that is not a prim path, has no prim on the composed stage, is
    not usable (inactive, only an `over`, or abstract) or is not a RenderVar;
    the message says which.

    ## Why is this bad?
    *"Specifies the RenderVars that should be consumed and combined into the
    final product."* (`pxr/usd/usdRender/schema.usda`). spec.cpp: *"Render
    product <%s> includes render var at path <%s>, but no suitable UsdRenderVar
    prim was found. Skipping."* (`pxr/usd/usdRender/spec.cpp`): the channel
    silently disappears from the output.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = [</Render/Vars/color>, </Render/Vars/diffuse>]
        }

        def Scope "Vars"
        {
            def RenderVar "color"
            {
                string sourceName = "Ci"
            }
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = </Render/Vars/color>
        }

        def Scope "Vars"
        {
            def RenderVar "color"
            {
                string sourceName = "Ci"
            }
        }
    }
    ```

    ## Fix safety
    Unsafe: the fix removes the bad target from `orderedVars` (when this
    relationship authors it rather than forwarding it), which changes the
    product's channel list; the author may instead have meant another path.
    A product none of whose targets is a usable RenderVar gets no fix:
    removing them would leave it with no RenderVars at all (PR004).
    """

    code = "PR005"
    name = "ordered-vars-invalid-target"
    severity = Severity.ERROR
    partial_composition = True
    fix_safety = "unsafe"
    prim_types = (schemas.RenderProduct,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        targets = ordered_var_targets(prim, ctx)
        # The usable RenderVars among the targets, kept once per lint for the PR
        # and VA rules: when every target is one (most products), none has a
        # problem (_problem is None exactly for those).
        if len(product_render_vars(prim, ctx)) == len(targets):
            return
        rel = prim_values(prim).relationship("orderedVars")
        bad = [(target, _problem(target)) for target in targets]
        # Removing the bad targets of a product without a good one would leave
        # orderedVars empty: PR004's error, a product with no channel at all.
        keeps_a_var = any(reason is None for _, reason in bad)
        authored = None  # the relationship's own targets, read for a bad target only
        for target, reason in bad:
            if reason is None:
                continue
            fix = None
            if authored is None:
                authored = set(authored_targets(rel))
            if keeps_a_var and target.path in authored:
                fix = Fix(
                    description=f"remove <{target.path}> from orderedVars",
                    safe=False,
                    apply=_remove_target(rel.GetPath(), target.path),
                )
            yield Diagnostic(
                message=f"orderedVars target <{target.path}> of {prim.GetPath()} {reason}: the "
                "channel "
                "is silently missing from the output; target a defined, active RenderVar or "
                "remove the target",
                at=rel,
                fix=fix,
            )
