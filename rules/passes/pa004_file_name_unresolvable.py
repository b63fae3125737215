"""PA004 file-name-unresolvable."""

from __future__ import annotations

import os
import re
from collections.abc import Iterator

from pxr import Ar, Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values

from ._default_value import _authored_layer

#: (Pattern text: re compiles it at first use, not at every start-up.)
_VARIABLE = r"\$\{(\w+)\}"


#: A URI scheme (``omniverse:``, ``https:``); two characters at least, so that
#: a Windows drive (``C:``) is not one.
_SCHEME = r"([A-Za-z][A-Za-z0-9+.\-]+):"
#: A Windows drive or UNC path (``C:\shows``, ``C:/shows``, ``\\server\share``).
_WINDOWS_ABSOLUTE = r"[A-Za-z]:[\\/]|\\\\"


def _platform_reason(path: str) -> str | None:
    """Why ``path`` cannot resolve here whatever files exist, for a path
    written for another resolver or platform (a Kit stage's ``omniverse://``,
    a Windows path), or None."""
    scheme = re.match(_SCHEME, path)
    if scheme and scheme.group(1).lower() not in {s.lower() for s in Ar.GetRegisteredURISchemes()}:
        return (
            f"uses the {scheme.group(1)}: scheme, and no asset resolver for it is registered "
            "where this lint runs; lint with that resolver's USD plugin or correct the path"
        )
    if os.sep == "/" and re.match(_WINDOWS_ABSOLUTE, path):
        return "is a Windows path, which does not resolve on this platform; correct the path"
    if os.sep == "/" and "\\" in path:
        return "uses backslashes, which are not path separators on this platform; write '/'"
    return None


def _unresolvable_reason(value: Sdf.AssetPath, layer: Sdf.Layer | None) -> str:
    """Why an authored asset path has no resolved path, and what to do."""
    authored = value.authoredPath
    path = value.evaluatedPath or authored
    platform = _platform_reason(path)
    # An absolute path or a URI is not looked up relative to the layer.
    relative = not os.path.isabs(path) and not re.match(_SCHEME, path)
    where = f" relative to {layer.GetDisplayName()}" if layer is not None and relative else ""
    if Sdf.VariableExpression.IsExpression(authored):
        errors = Sdf.VariableExpression(authored).GetErrors()
        if errors:
            return (
                f"is a variable expression USD cannot evaluate ({'; '.join(errors)}); "
                "correct the expression"
            )
        # usd-core leaves an unset variable in the evaluated path as written.
        unset = sorted(set(re.findall(_VARIABLE, value.evaluatedPath)))
        if unset:
            names = ", ".join(unset)
            return (
                f"evaluates to {value.evaluatedPath!r}: expression variable(s) {names} not "
                "set; define them in the root layer's expressionVariables"
            )
        if platform is not None:
            return f"evaluates to {value.evaluatedPath!r}, which {platform}"
        return (
            f"evaluates to {value.evaluatedPath!r}, which does not resolve{where}; "
            "create the file or correct the path"
        )
    if platform is not None:
        return platform
    return f"does not resolve{where}; create the file or correct the path"


class FileNameUnresolvable(Rule):
    """A RenderPass fileName does not resolve to an existing asset.

    ## What it does
    Reports an authored, non-empty RenderPass `fileName` whose resolved path
    is empty after composition: USD's asset resolver, with the stage's
    resolver context, anchors a relative path to the layer that authored the
    opinion. A variable expression (backquoted, with `${VAR}`) is evaluated by
    USD first; unset variables and expression errors are named in the
    message, and so is a path written for another resolver or platform (a
    URI scheme such as `omniverse:` that no resolver registered here reads,
    a Windows path). The same value passes once the file exists next to that
    layer.

    ## Why is this bad?
    *"The asset that contains the rendering prims or other information needed
    to render this pass."* (`pxr/usd/usdRender/schema.usda`, RenderPass
    `fileName`), and *"If fileName is present, the source should be found in
    the file there."* (same file, `renderSource`). A source that cannot be
    found cannot be rendered.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderPass "composite"
        {
            uniform token passType = "nuke"
            uniform asset fileName = @./comp/final_composite.nk@
            uniform string[] command = ["nuke", "-x", "{fileName}"]
        }
    }
    ```

    ## Use instead
    Author `fileName` only with a path that resolves, or render a
    RenderSettings prim of this stage:

    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
        }

        def RenderPass "beauty"
        {
            uniform token passType = "prman"
            rel renderSource = </Render/Settings>
        }
    }
    ```

    ## Fix safety
    No automatic fix: the file is missing or the path is wrong, and only the
    author knows which.
    """

    code = "PA004"
    name = "file-name-unresolvable"
    severity = Severity.ERROR
    partial_composition = True
    prim_types = (schemas.RenderPass,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        value = values.authored("fileName")
        if not isinstance(value, Sdf.AssetPath) or not value.authoredPath:
            return
        attr = values.attribute("fileName")
        layer = _authored_layer(attr)
        ctx.depends_on_asset(value, layer)  # the finding comes and goes with the file
        if value.resolvedPath:
            return
        reason = _unresolvable_reason(value, layer)
        yield Diagnostic(
            message=f"fileName @{value.authoredPath}@ {reason}",
            at=attr,
        )
