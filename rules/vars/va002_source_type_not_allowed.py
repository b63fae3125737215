"""VA002 source-type-not-allowed."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values

from .._corrections import unique_case_match
from ._case_fix import _case_fix


class SourceTypeNotAllowed(Rule):
    """A RenderVar's sourceType is not raw, primvar, lpe or intrinsic.

    ## What it does
    Reports an authored `sourceType` that is not one of the schema's
    `allowedTokens`: `raw`, `primvar`, `lpe`, `intrinsic`.

    ## Why is this bad?
    `allowedTokens = ["raw", "primvar", "lpe", "intrinsic"]`
    (`pxr/usd/usdRender/schema.usda`). Consumers branch on these exact tokens
    (hdPrman adds the `lpe:` and `primvars:` prefixes only for `lpe` and
    `primvar`), so any other value is treated like `raw` by some renderers and
    rejected by others.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "diffuse"
            {
                string sourceName = "diffuse"
                uniform token sourceType = "aov"
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
            def RenderVar "diffuse"
            {
                string sourceName = "diffuse"
                uniform token sourceType = "raw"
            }
        }
    }
    ```

    ## Fix safety
    Safe, conditional: a value that differs from an allowed token only in case
    (`LPE`) is corrected to it (`lpe`); otherwise there is no fix.
    """

    code = "VA002"
    name = "source-type-not-allowed"
    severity = Severity.ERROR
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = (schemas.RenderVar,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        attr = values.attribute("sourceType")
        value = values.authored("sourceType")
        if value is None:
            return
        allowed = values.schema_attribute("sourceType").allowed_tokens  # only for a value
        if value in allowed:
            return
        correction = unique_case_match(value, allowed)
        advice = (
            f"did you mean {correction!r}?"
            if correction
            else "use raw for a renderer output name, lpe for a light path expression or "
            "primvar for a primvar"
        )
        yield Diagnostic(
            message=f"sourceType {value!r} of RenderVar {prim.GetPath()} is not one of "
            f"{', '.join(allowed)}; {advice}",
            at=attr,
            fix=_case_fix(attr, correction, "sourceType"),
        )
