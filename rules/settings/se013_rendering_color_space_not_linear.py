"""SE013 rendering-color-space-not-linear."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, record, schemas

from .. import _colorspace
from ._working_color_space import _color_space_cache, _rendering_color_space


class RenderingColorSpaceNotLinear(Rule):
    """renderingColorSpace is a valid colour space with a non-linear transfer function.

    ## What it does
    Resolves a valid `renderingColorSpace` on a RenderSettings (`Gf.ColorSpace`
    for a built-in name or alias, `ComputeColorSpaceFromDefinitionAttributes`
    for a custom one) and fires when its gamma is not 1 or its linear bias is
    not 0 (`srgb_*`, `g22_*`, `g18_*`, `g24_*`). The data-like spaces `data`,
    `raw`, `identity` and `unknown` do not fire unless the option
    `flag-data-spaces` is set. The message suggests the linear space with the
    same primaries.

    ## Why is this bad?
    *"This is the (linear) color space a renderer should use to do internal
    calculations"* (`RenderSettings.md`); *"Describes a renderer's working
    (linear) colorSpace where all the renderer/shader math is expected to
    happen"* (`pxr/usd/usdRender/schema.usda`). Lighting maths in an encoded
    space gives wrong results.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform token renderingColorSpace = "srgb_rec709_scene"
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
            uniform token renderingColorSpace = "lin_rec709_scene"
        }
    }
    ```

    ## Fix safety
    No automatic fix: changing the working space changes the picture.

    ## Options
    `flag-data-spaces` (bool, default false): also report the data-like
    designations `data`, `raw`, `identity` and `unknown`, which are not colour
    spaces a renderer can work in. Off by default because the user guide's own
    example uses `renderingColorSpace = "raw"` (catalog, Ambiguous semantics 6).
    """

    @record(frozen=True)
    class Options:
        flag_data_spaces: bool = False

    code = "SE013"
    name = "rendering-color-space-not-linear"
    severity = Severity.WARNING
    partial_composition = True
    prim_types = (schemas.RenderSettings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        found = _rendering_color_space(prim)
        if found is None:
            return
        attr, name = found
        space = _colorspace.resolve(prim, name, _color_space_cache(ctx))
        if space is None:
            return  # SE012's finding
        if space.is_data_like:
            if self.options.flag_data_spaces:
                yield Diagnostic(
                    message=f'renderingColorSpace "{name}" designates data, not a working colour '
                    'space; use a linear space such as "lin_ap1_scene"',
                    at=attr,
                )
            return
        if space.is_linear:
            return
        linear = _colorspace.linear_counterpart(space)
        suggestion = f'"{linear}" (same primaries)' if linear else 'e.g. "lin_ap1_scene"'
        origin = f", defined on {space.defined_on}" if space.defined_on else ""
        yield Diagnostic(
            message=f'renderingColorSpace "{name}" is not linear (gamma {space.gamma:.4g}, linear '
            "bias "
            f"{space.linear_bias:.4g}{origin}); the working space must be linear: use "
            f"{suggestion}",
            at=attr,
        )
