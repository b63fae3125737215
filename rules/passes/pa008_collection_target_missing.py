"""PA008 collection-target-missing."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import authored_targets, prim_values

from .._passes import authored_pass_collections, dangling_object_reason


class CollectionTargetMissing(Rule):
    """A RenderPass collection includes or excludes a path that names nothing.

    ## What it does
    Reports each target of `collection:<name>:includes` or `:excludes`, for
    the four RenderPass collections, for which the composed stage has no prim
    or property (`stage.GetObjectAtPath`), or whose prim is inactive,
    `over`-only or abstract; the message says which, and names the inactive
    ancestor when that is why the path has no prim.

    ## Why is this bad?
    A RenderPass partitions *"scene contents across multiple images rendered
    from the scene"* (`pxr/usd/usdRender/schema.usda`, RenderPass). A
    dangling include silently drops objects from the pass (typically after a
    rename), a dangling exclude silently leaves them in.

    ## Example
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Xform "chars"
        {
        }
    }

    def Scope "Render"
    {
        def RenderPass "foreground"
        {
            uniform token passType = "prman"
            uniform bool collection:renderVisibility:includeRoot = 0
            prepend rel collection:renderVisibility:includes = </World/characters>
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Xform "chars"
        {
        }
    }

    def Scope "Render"
    {
        def RenderPass "foreground"
        {
            uniform token passType = "prman"
            uniform bool collection:renderVisibility:includeRoot = 0
            prepend rel collection:renderVisibility:includes = </World/chars>
        }
    }
    ```

    ## Fix safety
    No automatic fix: the renamed path is unknown.
    """

    code = "PA008"
    name = "collection-target-missing"
    severity = Severity.WARNING
    partial_composition = True
    prim_types = (schemas.RenderPass,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        for label, _ in authored_pass_collections(prim, ctx):
            for kind, effect in (
                ("includes", "drops these objects from"),
                ("excludes", "leaves these objects in"),
            ):
                name = f"{label}:{kind}"
                # A relationship that no spec names has no targets: most
                # collections author only their includes.
                if not values.may_be_authored(name):
                    continue
                rel = values.relationship(name)
                for target in authored_targets(rel):
                    reason = dangling_object_reason(ctx, target)
                    if reason is not None:
                        yield Diagnostic(
                            message=f"{label}:{kind} target <{target}> {reason}; it silently "
                            f"{effect} the pass; retarget it or remove it",
                            at=rel,
                        )
