"""ST002 composition-error-on-render-prim."""

from __future__ import annotations

import re
from collections.abc import Iterator

from pxr import Pcp, Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity
from usdrender_lint.api.files import lfs_pointer_problem
from usdrender_lint.api.resolve import USD_NAMESPACE, usd_string, usd_text

from ._render_prims import RENDER_SCOPE, is_render_type

#: Where an asset path's variable expression failed, as PcpErrorVariableExpressionError
#: says it (pxr/usd/pcp/errors.cpp: "... for reference at /Render/Settings in
#: @shot.usda@: ..."; a sublayer's names no prim): its site is empty in usd-core 26.11.
#: (Pattern texts, here and below: re compiles each at first use, not at every
#: start-up.)
_EXPRESSION_CONTEXT = r" for [\w ]+? (?:at (/\S*) )?in @"


def _composition_error_site(error) -> Sdf.Path | None:
    site = getattr(error, "rootSite", None)
    path = getattr(site, "path", None)
    if isinstance(path, Sdf.Path) and path.isEmpty:
        # An expression that cannot be evaluated: a sublayer's is the layer
        # stack's (the site /), a reference's or payload's the prim's.
        context = re.search(_EXPRESSION_CONTEXT, usd_text(error))
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


#: The arc an error's text names ("Could not open asset @a@ for reference ...",
#: "Unresolved payload prim path ...", "Could not load sublayer ...";
#: pxr/usd/pcp/errors.cpp), read outside its quoted asset and prim paths.
_ARC = r"\b(reference|payload|sublayer)\b"
_QUOTED = r"@[^@]*@|<[^>]*>|`[^`]*`"
#: A space USD leaves before the ";" or "." that ends the reason a layer could
#: not be read ("... in </X.a> ; skipping.").
_SPACE_BEFORE_STOP = r" +([;.])(?=\s|$)"


def _usd_words(error, session: Sdf.Layer | None = None) -> str:
    """USD's text of the error on one line, without its C++ namespace, the
    stage's session layer or the address of an anonymous layer, ending in a
    full stop."""
    text = " ".join(usd_text(error).split())
    text = re.sub(_SPACE_BEFORE_STOP, r"\1", USD_NAMESPACE.sub("", text))
    # A layer stack "@shot.usda@,@anon:...-session.usda@" is the user's layers
    # and the anonymous session layer of whoever opened the stage: the tool's
    # own, named after the file linted, or a host's (the Asset Validator opens
    # every stage with its own, anon:AssetValidator). A --fix-to layer stays.
    if session is not None and session.anonymous:
        text = text.replace(f",@{usd_string(lambda: session.identifier)}@", "")
    text = re.sub(_SESSION_IN_STACK, "", re.sub(_ANONYMOUS_ADDRESS, "anon:", text))
    return text if text.endswith((".", "!", "?")) else f"{text}."


#: The layer whose subLayers hold the failing entry, as USD names it:
#: "Could not load sublayer @a@ of layer @shot.usda@", "Error evaluating
#: expression `...` for sublayer in @shot.usda@" (pxr/usd/pcp/errors.cpp).
_LISTING_LAYER = r"(?: of layer | for sublayer in )@([^@]+)@"


def _listing_layer(stage: Usd.Stage, error) -> Sdf.Layer | None:
    """The layer of the stage's layer stack whose subLayers the error is
    about: the finding's place (else the root layer's, where a layer of the
    shot that is not the root, linted as a changed layer with ``roots``, lost
    its own broken sublayer). None when the error names none."""
    named = re.search(_LISTING_LAYER, usd_text(error))
    if named is None:
        return None
    for layer in stage.GetLayerStack(True):
        try:
            if layer.identifier == named.group(1):
                return layer
        except UnicodeDecodeError:  # a name that is not UTF-8: the root layer's place
            continue
    return None


def _consequence(error, text: str, scope: str) -> str:
    """What the error costs ``scope`` and what to do, by the error's type: an
    asset path to correct, a layer to repair, a prim path, a cycle to break."""
    kind = getattr(error, "errorType", None)
    arc_match = re.search(_ARC, re.sub(_QUOTED, "", text))
    arc = arc_match.group(1) if arc_match else "arc"
    # USD could open the file but not read it: "... -- <the parser's error>".
    unreadable = " -- " in text
    if kind == Pcp.ErrorType_InvalidSublayerPath:
        loses = f"{scope} loses the opinions of that sublayer"
        if unreadable:
            return f"{loses}; repair that layer or remove it from subLayers"
        return f"{loses}; correct its path or remove it from subLayers"
    if kind in (Pcp.ErrorType_InvalidAssetPath, Pcp.ErrorType_MutedAssetPath):
        loses = f"{scope} loses the opinions of that {arc}"
        if unreadable:
            return f"{loses}; repair the layer it names or remove the {arc}"
        return f"{loses}; correct its asset path or remove the {arc}"
    if kind == Pcp.ErrorType_UnresolvedPrimPath:
        loses = f"{scope} loses the opinions of that {arc}"
        if "<defaultPrim>" in text:
            return (
                f"{loses}: the layer it names has no defaultPrim; author one there "
                f"or name a prim in the {arc}"
            )
        return (
            f"{loses}: the layer it names has no prim at that path; name one it "
            f"defines or remove the {arc}"
        )
    if kind == Pcp.ErrorType_ArcCycle:
        return (
            f"USD drops the arc that closes the cycle, so {scope} loses its opinions; "
            "remove that arc"
        )
    if kind == Pcp.ErrorType_SublayerCycle:
        # The layer already counts once: nothing is lost, the repeat is skipped.
        return "USD skips the repeated sublayer; remove it from subLayers"
    if kind == Pcp.ErrorType_VariableExpressionError:
        return f"{scope} loses the opinions of that {arc}; correct the expression"
    if kind in (Pcp.ErrorType_InvalidReferenceOffset, Pcp.ErrorType_InvalidSublayerOffset):
        return (
            f"{scope} gets that {arc}'s opinions without the offset (times neither "
            "shifted nor scaled); correct the offset"
        )
    return f"{scope} may miss opinions it should compose; correct the arc USD names"


#: An anonymous layer's identifier holds its address (``anon:0x55f8ea155340:``),
#: which differs between runs; the message keeps only the layer's tag.
_ANONYMOUS_ADDRESS = r"\banon:0x[0-9a-fA-F]+:"
_SESSION_IN_STACK = r",@anon:[^@]*-session\.usda@"


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
    prim, so they are always reported, in the layer whose `subLayers` lists
    the one that failed. An asset path whose variable
    expression cannot be evaluated gets no site from usd-core (26.11); its
    error names one, read from it: a sublayer's is /, a reference's or
    payload's its prim. The message is USD's own (on one line, without its
    C++ namespace), then what the error costs and what to do by its kind: a
    missing file's asset path to correct, a layer that does not parse to
    repair, a prim path the layer does not define, a cycle to break (a
    sublayer cycle costs nothing: USD skips the repeat). An error
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
            text = _usd_words(error, ctx.stage.GetSessionLayer())
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
            said = _consequence(error, text, scope)
            yield Diagnostic(
                message=f"{text} {said[0].upper()}{said[1:]}",
                at=None if at_root else site,
                layer=_listing_layer(ctx.stage, error) if at_root else None,
            )
