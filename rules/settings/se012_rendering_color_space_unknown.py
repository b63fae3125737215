"""SE012 rendering-color-space-unknown."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas

from .. import _colorspace
from ._messages import _quoted
from ._working_color_space import _color_space_cache, _rendering_color_space


class RenderingColorSpaceUnknown(Rule):
    """renderingColorSpace is not a colour space USD knows.

    ## What it does
    Checks an authored, non-empty `renderingColorSpace` on a RenderSettings
    with `Usd.ColorSpaceAPI.IsValidColorSpaceName`: valid are the built-in
    `Gf.ColorSpaceNames` tokens (`lin_ap1_scene`, `lin_rec709_scene`, …), the
    display-name aliases `Gf.ColorSpace` accepts (`ACEScg`), and custom spaces
    a `ColorSpaceDefinitionAPI` declares on the settings prim or an ancestor.
    The message lists the nearest canonical tokens.

    ## Why is this bad?
    *"renderingColorSpace: The renderer working color space. This is the
    (linear) color space a renderer should use to do internal calculations"*
    (`RenderSettings.md`); *"OpenUSD, MaterialX, and OCIO have jointly agreed on
    a canonical set of interoperable color spaces"*
    (`docs/user_guides/color_user_guide.rst`). An OCIO config name such as
    `ACES - ACEScg` is not a USD colour space and is not portable.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform token renderingColorSpace = "ACES - ACEScg"
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
            uniform token renderingColorSpace = "lin_ap1_scene"
        }
    }
    ```

    ## Fix safety
    No automatic fix: which space was meant is a guess; the message suggests
    the nearest canonical names.
    """

    code = "SE012"
    name = "rendering-color-space-unknown"
    severity = Severity.WARNING
    partial_composition = True
    prim_types = (schemas.RenderSettings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        found = _rendering_color_space(prim)
        if found is None:
            return
        attr, name = found
        if _colorspace.is_valid_name(prim, name, _color_space_cache(ctx)):
            return
        nearest = _colorspace.nearest_names(name)
        hint = f"did you mean {_quoted(nearest)}? Otherwise " if nearest else ""
        yield Diagnostic(
            message=f'renderingColorSpace "{name}" is not a USD colour space (not a Gf.ColorSpace '
            "name "
            f"or alias, and no ColorSpaceDefinitionAPI on {prim.GetPath()} or its ancestors "
            f'defines it); {hint}use a canonical linear token such as "lin_ap1_scene"',
            at=attr,
        )
