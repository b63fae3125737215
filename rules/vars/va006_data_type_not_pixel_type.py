"""VA006 data-type-not-pixel-type."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values

from .._corrections import set_value

#: Scalar types that cannot be a raster channel (catalog, VA006).
NON_PIXEL_SCALAR_TYPES = frozenset(
    {
        "string",
        "token",
        "asset",
        "opaque",
        "group",
        "pathExpression",
        "timecode",
        "duration",
        "frame4d",
        "bool",
        "matrix2d",
        "matrix3d",
        "matrix4d",
        "quatd",
        "quatf",
        "quath",
    }
)


class DataTypeNotPixelType(Rule):
    """A RenderVar's dataType cannot be stored per pixel.

    ## What it does
    Reports an authored `dataType` that is a valid type name (it passes VA005)
    but cannot be a per-pixel channel: an array type (`float[]`) or a
    non-numeric or non-vector scalar (`string, token, asset, opaque, group,
    pathExpression, timecode, duration, frame4d, bool`, matrices and
    quaternions).

    ## Why is this bad?
    A RenderVar is *"a quantity or 'channel' of computed data"* (RenderVar
    prim definition, usd-core 26.11) stored per pixel; image formats hold
    numeric scalars or small tuples (half, float, int, uint; 2 to 4
    components). Arrays and strings cannot be written to a raster channel.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "depth"
            {
                token dataType = "float[]"
                string sourceName = "z"
            }
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "depth"
            {
                token dataType = "float"
                string sourceName = "z"
            }
        }
    }
    ```

    ## Fix safety
    Unsafe: an array of a numeric type `T[]` becomes `T`, which changes the
    channel the renderer writes; other types have no fix.
    """

    code = "VA006"
    name = "data-type-not-pixel-type"
    severity = Severity.WARNING
    partial_composition = True
    fix_safety = "unsafe"
    prim_types = (schemas.RenderVar,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        attr = values.attribute("dataType")
        value = values.authored("dataType")
        type_name = Sdf.ValueTypeNames.Find(value) if value else None
        if not type_name:
            return
        scalar = str(type_name.scalarType)
        numeric = scalar not in NON_PIXEL_SCALAR_TYPES
        if numeric and not type_name.isArray:
            return
        fix = None
        if numeric:
            problem, advice = "is an array type", f"use {scalar!r}"
            fix = Fix(
                description=f"set dataType to {scalar!r}",
                safe=False,
                apply=set_value(attr.GetPath(), scalar),
            )
        else:
            problem = "is not a numeric scalar or vector type"
            advice = "use a numeric type such as float, int, float3 or color3f"
        yield Diagnostic(
            message=f"dataType {value!r} of RenderVar {prim.GetPath()} {problem} and cannot be a "
            f"per-pixel channel; {advice}",
            at=attr,
            fix=fix,
        )
