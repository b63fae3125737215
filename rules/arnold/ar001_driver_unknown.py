"""AR001 arnold-driver-unknown."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, record, schemas
from usdrender_lint.api.resolve import authored_value

from .._corrections import set_value
from ..stage.st010_unknown_render_prim_type import edit_distance

#: The output drivers arnold-usd itself names: the default driver_exr, deep
#: products' driver_deepexr, and the drivers it picks from a productName's
#: extension (libs/translator/reader/read_options.cpp, DeduceDriverFromFilename).
ARNOLD_DRIVERS = ("driver_exr", "driver_deepexr", "driver_tiff", "driver_jpeg", "driver_png")


class DriverUnknown(Rule):
    """A RenderProduct's arnold:driver names no Arnold output driver.

    ## What it does
    Under the `arnold` profile, reports a RenderProduct whose authored
    `arnold:driver` is not one of Arnold's output drivers (`driver_exr`,
    `driver_deepexr`, `driver_tiff`, `driver_jpeg`, `driver_png`, plus the
    option `extra-drivers` for a studio's driver plugins), or names one as
    another type than `string` (e.g. `token arnold:driver = "driver_exr"`).

    ## Why is this bad?
    arnold-usd creates the product's driver from the node type `arnold:driver`
    names. In husk's render delegate an unknown type logs *"Unknown Arnold
    Driver Type"* and the product is skipped (`_ParseDelegateRenderProducts`,
    `libs/render_delegate/render_delegate.cpp`); the USD procedural's
    `ReadDriverFromRenderProduct` gets no node and skips the product too
    (`libs/translator/reader/read_options.cpp`). Either way its image is never
    written. The procedural reads the attribute only as a string
    (`driverAttr.Get<std::string>(&driverTypeName, ...)` in
    `ReadDriverFromRenderProduct`): a `token` names no driver there, so kick
    skips the product though husk's delegate accepts both types.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            string arnold:driver = "driver_tif"
            token productName = "beauty.tif"
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
            string arnold:driver = "driver_tiff"
            token productName = "beauty.tif"
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when exactly one known driver is one edit away from the
    value (`driver_tif` -> `driver_tiff`), the fix authors it; otherwise there
    is no fix.

    ## Options
    `extra-drivers` (list of strings, default empty): more driver node types
    the studio's Arnold installs (plugins).
    """

    code = "AR001"
    name = "arnold-driver-unknown"
    severity = Severity.ERROR
    partial_composition = True
    fix_safety = "safe-conditional"
    profile = "arnold"
    prim_types = (schemas.RenderProduct,)

    @record(frozen=True)
    class Options:
        extra_drivers: tuple[str, ...] = ()

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("arnold:driver")
        value = authored_value(attr)
        if value is None:
            return
        known = (*ARNOLD_DRIVERS, *self.options.extra_drivers)
        if str(value) in known:
            if attr.GetTypeName() != Sdf.ValueTypeNames.String:
                # The USD procedural reads it with driverAttr.Get<std::string>, which
                # fails on any other type: no driver, and the product is skipped.
                yield Diagnostic(
                    message=f"arnold:driver of {prim.GetPath()} is a {attr.GetTypeName()}, not "
                    "a string: arnold-usd's USD procedural (kick) reads only a string and skips "
                    "the product, writing no image; author it as string arnold:driver = "
                    f"{str(value)!r}",
                    at=attr,
                )
            return
        near = [d for d in known if edit_distance(str(value), d) == 1]
        fix = None
        advice = f"use one of {', '.join(known)}"
        if len(near) == 1:
            advice = f"did you mean {near[0]!r}?"
            fix = Fix(
                description=f"set arnold:driver to {near[0]!r}",
                safe=True,
                apply=set_value(attr.GetPath(), type(value)(near[0])),
            )
        yield Diagnostic(
            message=f"arnold:driver {str(value)!r} of {prim.GetPath()} is no Arnold output "
            f"driver, so arnold-usd skips the product and writes no image; {advice}",
            at=attr,
            fix=fix,
        )
