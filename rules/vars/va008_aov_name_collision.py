"""VA008 aov-name-collision."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, record, schemas

from .._aov import AovNaming, channel_name, product_render_vars, targeted_vars


def _channels_may_collide(ctx: Context, naming: AovNaming) -> bool:
    """Whether two of the vars that products target have the same channel name
    under ``naming``: else no product's vars can (asked once per lint, not for
    every var of every product)."""
    found = targeted_vars(ctx)
    if found is None:
        return True  # the vars are not known here: check each product
    channels = [channel_name(var, naming, ctx) for var in found]
    return len(set(channels)) < len(channels)


class AovNameCollision(Rule):
    """Two RenderVars of one product produce channels with the same name.

    ## What it does
    Reports two forwarded `orderedVars` targets of the same product that are
    RenderVar prims with the same prim name (e.g.
    `/Render/Vars/lighting/diffuse` and `/Render/Vars/albedo/diffuse`). With
    the option `aov-naming = "sourceName"` it also uses hdPrman's naming (the
    prim name for `lpe` vars, `sourceName` for the others) and reports two
    vars that collide under it.

    ## Why is this bad?
    *"The name of the RenderVar prim drives the name of the data variable
    that the renderer will produce."* (`pxr/usd/usdRender/schema.usda`, also
    `RenderVar.md`). Two vars named `diffuse` in one product produce two
    channels with the same name: one overwrites the other or the driver
    rejects the layout.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = [</Render/Vars/lighting/diffuse>, </Render/Vars/albedo/diffuse>]
        }

        def Scope "Vars"
        {
            def Scope "lighting"
            {
                def RenderVar "diffuse"
                {
                    string sourceName = "C<RD>[<L.>O]"
                    uniform token sourceType = "lpe"
                }
            }

            def Scope "albedo"
            {
                def RenderVar "diffuse"
                {
                    string sourceName = "albedo"
                }
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
            rel orderedVars = [</Render/Vars/lighting/diffuse>, </Render/Vars/albedo/albedo>]
        }

        def Scope "Vars"
        {
            def Scope "lighting"
            {
                def RenderVar "diffuse"
                {
                    string sourceName = "C<RD>[<L.>O]"
                    uniform token sourceType = "lpe"
                }
            }

            def Scope "albedo"
            {
                def RenderVar "albedo"
                {
                    string sourceName = "albedo"
                }
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: renaming a prim changes a channel name that downstream
    comps rely on.

    ## Options
    `aov-naming` (`"primName"`, default, or `"sourceName"`): also check the
    hdPrman naming (catalog, Ambiguous semantics 7).
    """

    code = "VA008"
    name = "aov-name-collision"
    severity = Severity.ERROR
    partial_composition = True
    prim_types = (schemas.RenderProduct,)

    @record(frozen=True)
    class Options:
        aov_naming: AovNaming = "primName"

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        namings: tuple[AovNaming, ...] = ("primName",)
        if self.options.aov_naming == "sourceName":
            namings = ("primName", "sourceName")
        reported: set[tuple[Sdf.Path, Sdf.Path]] = set()
        for naming in namings:
            if not ctx.cached(_channels_may_collide, naming):
                continue  # no two targeted vars share a channel name (most stages)
            render_vars = product_render_vars(prim, ctx)
            owners: dict[str, Usd.Prim] = {}
            for var in render_vars:
                channel = channel_name(var, naming, ctx)
                first = owners.setdefault(channel, var)
                if first is var:
                    continue  # the first var of its channel (paths are built for a collision)
                pair = (first.GetPath(), var.GetPath())
                if first.GetPath() == var.GetPath() or pair in reported:
                    continue
                reported.add(pair)
                how = (
                    "prim name"
                    if naming == "primName"
                    else "channel name under hdPrman's naming (sourceName for non-LPE vars)"
                )
                yield Diagnostic(
                    message=f"RenderVars {first.GetPath()} and {var.GetPath()} of "
                    f"{prim.GetPath()} share "
                    f"the {how} {channel!r}: the product gets two channels of that name and one "
                    "overwrites the other; rename one of them",
                    at=prim.GetRelationship("orderedVars"),
                )
