"""VA007 scalar-source-default-color3f."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values

from .._aov import checked_value
from .._corrections import set_value

#: Names of scalar quantities and the type the fix authors (None: ambiguous).
SCALAR_QUANTITY_TYPES = {
    "z": "float",
    "depth": "float",
    "a": "float",
    "alpha": "float",
    "coverage": "float",
    "id": "int",
    "primid": "int",
    "instanceid": "int",
    "elementid": "int",
    "mask": None,
}


class ScalarSourceDefaultColor3f(Rule):
    """A scalar-named RenderVar leaves dataType at the color3f fallback.

    ## What it does
    Reports a RenderVar with no authored `dataType` (so the fallback
    `color3f` applies) whose prim name or `sourceName` is, ignoring case, the
    name of a scalar quantity: `z, depth, a, alpha, id, primId, instanceId,
    elementId, coverage, mask`. A type-mismatched `dataType` opinion is
    SE016's finding.

    ## Why is this bad?
    The fallback is `color3f` (`uniform token dataType = "color3f"`,
    `pxr/usd/usdRender/schema.usda`), so an unauthored depth, alpha or id var
    is written as a 3-channel float colour: triple storage, and integer ids
    converted to float lose precision above 2^24. The official examples always
    author it: *"alpha" ... `token dataType = "float"`*, *"id" ... `token
    dataType = "int"`* (`RenderVar.md`).

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "depth"
            {
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
    Safe, conditional: the fix authors `float` for `z/depth/a/alpha/coverage`
    and `int` for `id/primId/instanceId/elementId`, making explicit the type
    the author evidently meant; `mask`, or names implying different types,
    get no fix.
    """

    code = "VA007"
    name = "scalar-source-default-color3f"
    severity = Severity.WARNING
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = (schemas.RenderVar,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        if values.has_value("dataType") or values.mismatched("dataType") is not None:
            return
        attr = values.attribute("dataType")
        candidates = (prim.GetName(), checked_value(prim, "sourceName", ctx) or "")
        matched = [n for n in candidates if n.lower() in SCALAR_QUANTITY_TYPES]
        if not matched:
            return
        types = {SCALAR_QUANTITY_TYPES[n.lower()] for n in matched}
        intended = types.pop() if len(types) == 1 else None
        fix = None
        if intended is not None:
            fix = Fix(
                description=f"author dataType = {intended!r}",
                safe=True,
                apply=set_value(attr.GetPath(), intended),
            )
        advice = (
            f'author token dataType = "{intended}"'
            if intended
            else ('author the intended dataType, e.g. token dataType = "float"')
        )
        yield Diagnostic(
            message=f"RenderVar {prim.GetPath()} ({matched[0]!r}) is a scalar quantity but leaves "
            f'dataType at the fallback "color3f": it is written as a 3-channel colour; {advice}',
            at=prim,
            fix=fix,
        )
