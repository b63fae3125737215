"""SE001 resolution-non-positive."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, record, schemas
from usdrender_lint.api.resolve import items, prim_values

from ._messages import _fmt


class ResolutionNonPositive(Rule):
    """resolution has a zero or negative component.

    ## What it does
    Checks `resolution` (`int2`, fallback `(2048, 1080)`): on a RenderSettings
    the composed value (authored or fallback), on a RenderProduct only an
    authored value, since only authored product values override the settings.
    It fires when a component is `<= 0`. With the option `require-authored`,
    a RenderSettings that leaves `resolution` at its fallback is reported too.

    ## Why is this bad?
    *"The image resolution in pixels. The render camera's screen window … is
    sampled by the renderer to a raster image of this resolution."*
    (`RenderSettings.md`). `UsdRenderComputeSpec` skips the aspect-ratio conform
    when `res[0] <= 0 || res[1] <= 0` (`pxr/usd/usdRender/spec.cpp`), and no
    image can have a non-positive size.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform int2 resolution = (1920, 0)
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
    No automatic fix: the intended size cannot be guessed.

    ## Options
    `require-authored` (bool, default false): also report a RenderSettings
    whose `resolution` is unauthored. The fallback `(2048, 1080)` is a DCI-2K
    container, not HD, and rarely what a studio means (catalog, Ambiguous
    semantics 2).
    """

    @record(frozen=True)
    class Options:
        require_authored: bool = False

    code = "SE001"
    name = "resolution-non-positive"
    severity = Severity.ERROR
    partial_composition = True
    prim_types = (schemas.RenderSettingsBase,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        is_settings = values.is_a(schemas.RenderSettings)
        value = values.composed("resolution") if is_settings else values.authored("resolution")
        if value is None:
            return
        if min(items(value)) <= 0:
            yield Diagnostic(
                message=f"resolution {_fmt(value)} has a component <= 0; author a positive pixel "
                "size "
                "such as (1920, 1080)",
                at=values.attribute("resolution"),
            )
        elif is_settings and self.options.require_authored and not values.has_value("resolution"):
            yield Diagnostic(
                message=f"resolution is not authored on {prim.GetPath()}, so renderers use the "
                "fallback "
                f"{_fmt(value)} (DCI-2K); author the intended size, e.g. "
                "uniform int2 resolution = (1920, 1080)",
                at=prim,
            )
