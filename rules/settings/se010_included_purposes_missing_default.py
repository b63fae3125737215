"""SE010 included-purposes-missing-default."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd, Vt

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values

from .._corrections import set_value
from ._messages import _fmt


class IncludedPurposesMissingDefault(Rule):
    """An authored includedPurposes does not list "default".

    ## What it does
    Reports a RenderSettings whose authored `includedPurposes` lacks
    `"default"`, including an authored empty array. The fallback
    `["default", "render"]` never fires this rule.

    ## Why is this bad?
    The schema says *"Only imageable prims with purpose set to one of the
    includedPurposes values will be rendered"* (RenderSettings prim
    definition, usd-core 26.11) while the user docs say *"Renderers are
    expected to render default purpose prims for all render situations."*
    (`pxr/usd/usdRender/userDoc/overview.md`). Listing `default` is correct
    under both readings; omitting it makes the result renderer-dependent.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform token[] includedPurposes = ["render"]
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
            uniform token[] includedPurposes = ["default", "render"]
        }
    }
    ```

    ## Fix safety
    Safe: the fix prepends `"default"` to the authored array in the layer that
    authors it, which is right under both readings of the docs.
    """

    code = "SE010"
    name = "included-purposes-missing-default"
    severity = Severity.WARNING
    partial_composition = True
    fix_safety = "safe"
    prim_types = (schemas.RenderSettings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        attr = values.attribute("includedPurposes")
        purposes = values.authored("includedPurposes")
        if purposes is None or "default" in purposes:
            return
        fixed = Vt.TokenArray(["default", *purposes])
        yield Diagnostic(
            message=f'includedPurposes {_fmt(purposes)} does not list "default"; whether prims '
            "without an authored purpose render then depends on the renderer: author "
            f"{_fmt(fixed)}",
            at=attr,
            fix=Fix(
                description='prepend "default"', safe=True, apply=set_value(attr.GetPath(), fixed)
            ),
        )
