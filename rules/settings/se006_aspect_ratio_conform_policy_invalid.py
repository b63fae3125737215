"""SE006 aspect-ratio-conform-policy-invalid."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values

from .._corrections import set_value


class AspectRatioConformPolicyInvalid(Rule):
    """An authored aspectRatioConformPolicy is not one of the schema's tokens.

    ## What it does
    Checks an authored `aspectRatioConformPolicy` on a RenderSettings or
    RenderProduct against the attribute's `allowedTokens`, read at run time
    from the prim definition (`expandAperture`, `cropAperture`,
    `adjustApertureWidth`, `adjustApertureHeight`, `adjustPixelAspectRatio` in
    usd-core 26.11). The comparison is case-sensitive.

    ## Why is this bad?
    `allowedTokens = ["expandAperture", "cropAperture", "adjustApertureWidth",
    "adjustApertureHeight", "adjustPixelAspectRatio"]`
    (`pxr/usd/usdRender/schema.usda`). `UsdRenderComputeSpec` matches these
    tokens exactly; any other value falls through every branch, so no conform
    is applied at all, not even the fallback `expandAperture`.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform token aspectRatioConformPolicy = "cropaperture"
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
            uniform token aspectRatioConformPolicy = "cropAperture"
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when the value matches exactly one allowed token
    ignoring case (`cropaperture`), the fix authors that token; otherwise no
    fix is offered.
    """

    code = "SE006"
    name = "aspect-ratio-conform-policy-invalid"
    severity = Severity.ERROR
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = (schemas.RenderSettingsBase,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        name = "aspectRatioConformPolicy"
        values = prim_values(prim)
        policy = values.authored(name)
        if policy is None:
            return
        allowed = values.schema_attribute(name).allowed_tokens
        if not allowed or policy in allowed:
            return
        attr = values.attribute(name)
        same_letters = [t for t in allowed if t.lower() == str(policy).lower()]
        fix = None
        if len(same_letters) == 1:
            fix = Fix(
                description=f'set to "{same_letters[0]}"',
                safe=True,
                apply=set_value(attr.GetPath(), same_letters[0]),
            )
        hint = f'did you mean "{same_letters[0]}"? ' if same_letters else ""
        yield Diagnostic(
            message=f'aspectRatioConformPolicy "{policy}" is not an allowed token, so no '
            "aspect-ratio "
            f"conform is applied at all; {hint}use one of {', '.join(allowed)} "
            "(case-sensitive)",
            at=attr,
            fix=fix,
        )
