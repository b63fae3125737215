"""SE014 products-target-invalid."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values, typed_target_problem


class ProductsTargetInvalid(Rule):
    """A products target is missing, unusable or not a RenderProduct.

    ## What it does
    Resolves each forwarded target of a RenderSettings' `products` and
    reports it when it is not a prim path, no prim exists there, the prim is
    inactive, only an `over` or abstract, or it is not a RenderProduct.

    ## Why is this bad?
    *"This relationship should target UsdRenderProduct prims."*
    (`pxr/usd/usdRender/schema.usda`). `UsdRenderComputeSpec` silently skips a
    target that is not a RenderProduct (`pxr/usd/usdRender/spec.cpp`) and
    Hydra's traversal never sees an unusable one, so that output is never
    rendered.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel products = </Render/Vars/beauty>
        }

        def Scope "Vars"
        {
            def RenderVar "beauty"
            {
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
        def RenderSettings "Settings"
        {
            rel products = </Render/Beauty>
        }

        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = </Render/Vars/beauty>
        }

        def Scope "Vars"
        {
            def RenderVar "beauty"
            {
                string sourceName = "Ci"
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: which product was meant cannot be guessed.
    """

    code = "SE014"
    name = "products-target-invalid"
    severity = Severity.ERROR
    partial_composition = True
    prim_types = (schemas.RenderSettings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        for target in values.targets("products"):
            problem = typed_target_problem(target, schemas.RenderProduct, "a RenderProduct")
            if problem is None:
                continue
            yield Diagnostic(
                message=f"products target {target.path} {problem}, so that output is never "
                "rendered; "
                "target a defined, active RenderProduct prim",
                at=values.relationship("products"),
            )
