"""AR002 arnold-filter-not-string."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas


class FilterNotString(Rule):
    """A RenderVar's arnold:filter is not a string, so husk ignores it.

    ## What it does
    Under the `arnold` profile, reports a RenderVar (or a RenderProduct) whose
    authored `arnold:filter` has a value type other than `string`, e.g.
    `token arnold:filter = "gaussian_filter"`.

    ## Why is this bad?
    husk's Arnold render delegate reads `arnold:filter` only when it holds a
    string (*"We need to make sure that it's holding a string"*, `_CreateFilter`
    and `_GetOptionalSetting<std::string>` in arnold-usd
    `libs/render_delegate/render_pass.cpp`); a token is skipped and the AOV is
    filtered with the default `box_filter`, silently. (The USD procedural
    accepts both, so the same file renders differently in kick and husk.)

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderVar "beauty"
        {
            token arnold:filter = "gaussian_filter"
            string sourceName = "RGBA"
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderVar "beauty"
        {
            string arnold:filter = "gaussian_filter"
            string sourceName = "RGBA"
        }
    }
    ```

    ## Fix safety
    No automatic fix: the attribute must be re-authored with the string type
    in the layer that declares it.
    """

    code = "AR002"
    name = "arnold-filter-not-string"
    severity = Severity.WARNING
    partial_composition = True
    profile = "arnold"
    prim_types = (schemas.RenderVar, schemas.RenderProduct)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("arnold:filter")
        if not attr or not attr.HasAuthoredValue():
            return
        type_name = attr.GetTypeName()
        if type_name == Sdf.ValueTypeNames.String:
            return
        yield Diagnostic(
            message=f"arnold:filter of {prim.GetPath()} is a {type_name}, not a string: husk's "
            "Arnold delegate ignores it and filters with box_filter; author it as "
            f"string arnold:filter = {str(attr.Get())!r}",
            at=attr,
        )
