"""VA005 data-type-unknown."""

from __future__ import annotations

from collections.abc import Iterator
from functools import cache

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values

from .._corrections import unique_case_match
from ._case_fix import _case_fix


@cache
def _value_type_names() -> frozenset[str]:
    """Every type name Sdf knows, arrays and role names included."""
    names = (getattr(Sdf.ValueTypeNames, n) for n in dir(Sdf.ValueTypeNames))
    return frozenset(str(n) for n in names if isinstance(n, Sdf.ValueTypeName))


class DataTypeUnknown(Rule):
    """A RenderVar's dataType is not a USD value type name.

    ## What it does
    Reports an authored `dataType` (`uniform token`, fallback `color3f`, no
    `allowedTokens`) that `Sdf.ValueTypeNames.Find` does not know. The lookup is
    case-sensitive: `Float`, `rgb` and `vec3` fail.

    ## Why is this bad?
    *"The type of this channel, as a USD attribute type."*
    (`pxr/usd/usdRender/schema.usda`; `RenderVar.md`: *"as a USD attribute
    type (color3f, float, etc.)"*). Consumers map it to a pixel format (an
    HdFormat or a display-driver channel type); an unknown name has no
    mapping.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "color"
            {
                token dataType = "rgb"
                string sourceName = "Ci"
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
            def RenderVar "color"
            {
                token dataType = "color3f"
                string sourceName = "Ci"
            }
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when exactly one type name matches ignoring case
    (`Float` -> `float`, `Color3F` -> `color3f`) the fix authors it; otherwise
    there is no fix.
    """

    code = "VA005"
    name = "data-type-unknown"
    severity = Severity.ERROR
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = (schemas.RenderVar,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        attr = values.attribute("dataType")
        value = values.authored("dataType")
        if value is None or Sdf.ValueTypeNames.Find(value):
            return
        correction = unique_case_match(value, _value_type_names())
        advice = (
            f"did you mean {correction!r}?"
            if correction
            else "use a USD attribute type such as color3f, float, int or normal3f"
        )
        yield Diagnostic(
            message=f"dataType {value!r} of RenderVar {prim.GetPath()} is not a USD value type "
            "name; " + advice,
            at=attr,
            fix=_case_fix(attr, correction, "dataType"),
        )
