"""ST002 composition-error-on-render-prim."""

from __future__ import annotations

import re
from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity
from usdrender_lint.api.files import lfs_pointer_problem
from usdrender_lint.api.resolve import usd_text

from ._render_prims import RENDER_SCOPE, is_render_type

#: Where an asset path's variable expression failed, as PcpErrorVariableExpressionError
#: says it (pxr/usd/pcp/errors.cpp: "... for reference at /Render/Settings in
#: @shot.usda@: ..."; a sublayer's names no prim): its site is empty in usd-core 26.11.
_EXPRESSION_CONTEXT = re.compile(r" for [\w ]+? (?:at (/\S*) )?in @")


def _composition_error_site(error) -> Sdf.Path | None:
    site = getattr(error, "rootSite", None)
    path = getattr(site, "path", None)
    if isinstance(path, Sdf.Path) and path.isEmpty:
        # An expression that cannot be evaluated: a sublayer's is the layer
        # stack's (the site /), a reference's or payload's the prim's.
        context = _EXPRESSION_CONTEXT.search(usd_text(error))
        if context is None:
            return None
        at = context.group(1)
        return Sdf.Path(at) if at and Sdf.Path.IsValidPathString(at) else Sdf.Path.absoluteRootPath
    return path if isinstance(path, Sdf.Path) else None


def _first_instance_site(stage: Usd.Stage, site: Sdf.Path) -> tuple[Sdf.Path, Sdf.Path] | None:
    """(the instance, its first sibling instance) when ``site`` lies in an
    instance: USD composes a prototype once, from whichever of its instances a
    thread reaches first, and reports the prototype's errors there; the first
    instance by path is the same on every run."""
    prim = stage.GetPrimAtPath(site)
    if not prim or not (prim.IsInstance() or prim.IsInstanceProxy()):
        return None
    while prim and not prim.IsInstance():
        prim = prim.GetParent()
    prototype = prim.GetPrototype() if prim else None
    if not prototype:
        return None
    first = min(instance.GetPath() for instance in prototype.GetInstances())
    return (prim.GetPath(), first) if first != prim.GetPath() else None


def _lfs_pointers(text: str) -> str:
    """ " (@a.usda@ is a Git LFS pointer ...)" for each asset USD's error names
    that is one: USD says only that it is not a valid layer."""
    said = ""
    for asset in dict.fromkeys(re.findall(r"@([^@]+)@", text)):
        if lfs_pointer_problem(asset):
            said += f" (@{asset}@ is a Git LFS pointer, not the layer: run `git lfs pull`)"
    return said


#: An anonymous layer's identifier holds its address (``anon:0x55f8ea155340:``),
#: which differs between runs; the message keeps only the layer's tag.
_ANONYMOUS_ADDRESS = re.compile(r"\banon:0x[0-9a-fA-F]+:")


def _render_prim_paths(stage: Usd.Stage) -> list[Sdf.Path]:
    """Paths of every render prim, inactive, `over` and abstract ones included
    (``TraverseAll``); the schema test is cached per type name."""
    by_type_name: dict[str, bool] = {}
    paths = []
    for prim in stage.TraverseAll():
        type_name = prim.GetTypeName()
        hit = by_type_name.get(type_name)
        if hit is None:
            hit = by_type_name[type_name] = is_render_type(prim)
        if hit:
            paths.append(prim.GetPath())
    return paths


class CompositionErrorOnRenderPrim(Rule):
    """A composition error hits a render prim, its ancestors or descendants, or /Render.

    ## What it does
    Reports each of `stage.GetCompositionErrors()` whose site is under
    `/Render`, or is a RenderSettings, RenderProduct, RenderVar or RenderPass
    (inactive ones included), or an ancestor or descendant of one. Layer-stack
    errors such as a missing sublayer have the site `/`, an ancestor of every
    prim, so they are always reported. An asset path whose variable
    expression cannot be evaluated gets no site from usd-core (26.11); its
    error names one, read from it: a sublayer's is /, a reference's or
    payload's its prim. The message is USD's own. An error
    inside an instance is reported at the first instance of its prototype by
    path: USD composes a prototype from whichever instance one of its threads
    reaches first, and reports its errors there, which differs between runs.

    ## Why is this bad?
    A render prim whose reference, payload or inherit fails to compose
    silently loses every opinion that arc supplies: a facility RenderSettings
    referenced from a shared layer reverts to schema fallbacks (2048x1080, no
    camera, no products). OpenUSD reports it only as a stage warning (*"Could
    not open asset @...@ for reference introduced by ..."*,
    `pxr/usd/usd/stage.cpp`), which CI logs usually ignore.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings" (
            references = @./facility/shot_render_settings.usda@</Render/Settings>
        )
        {
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform int2 resolution = (1920, 1080)
        }
    }
    ```

    ## Fix safety
    No automatic fix: repair the asset path or remove the arc.
    """

    code = "ST002"
    name = "composition-error-on-render-prim"
    severity = Severity.ERROR
    partial_composition = True

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        errors = ctx.composition_errors
        if not errors:
            return
        render_paths: list[Sdf.Path] | None = None
        for error in errors:
            site = _composition_error_site(error)
            if site is None:
                continue
            text = _ANONYMOUS_ADDRESS.sub("anon:", " ".join(usd_text(error).split()))
            moved = _first_instance_site(ctx.stage, site)
            if moved is not None:
                reported, first = moved
                site = site.ReplacePrefix(reported, first)
                for end in (">", "/", "."):
                    text = text.replace(f"<{reported}{end}", f"<{first}{end}")
            if site != Sdf.Path.absoluteRootPath and not site.HasPrefix(RENDER_SCOPE):
                if render_paths is None:
                    render_paths = _render_prim_paths(ctx.stage)
                if not any(site.HasPrefix(p) or p.HasPrefix(site) for p in render_paths):
                    continue
            at_root = site == Sdf.Path.absoluteRootPath
            scope = "every prim" if at_root else f"render data at <{site}>"
            text += _lfs_pointers(text)
            yield Diagnostic(
                message=f"{text} {scope[0].upper()}{scope[1:]} loses the "
                "opinions this layer or arc would supply; repair the asset path or remove it",
                at=None if at_root else site,
            )
