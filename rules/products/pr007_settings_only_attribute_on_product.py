"""PR007 settings-only-attribute-on-product."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values

#: RenderSettings-only properties: UsdRenderComputeSpec never reads them on a product.
SETTINGS_ONLY_PROPERTIES = (
    "includedPurposes",
    "materialBindingPurposes",
    "renderingColorSpace",
    "products",
)


class SettingsOnlyAttributeOnProduct(Rule):
    """A RenderProduct authors a property only RenderSettings has.

    ## What it does
    Reports an authored `includedPurposes`, `materialBindingPurposes`,
    `renderingColorSpace` or `products` property on a RenderProduct. These are
    RenderSettings properties; on a product they are custom, non-schema
    properties.

    ## Why is this bad?
    includedPurposes: *"Note this cannot be specified per-RenderProduct because
    it is a statement of which geometry is present."*
    (`pxr/usd/usdRender/schema.usda`). `UsdRenderComputeSpec` reads purposes
    only from the settings prim and its namespaced-settings pass skips
    un-namespaced attributes (`pxr/usd/usdRender/spec.cpp`), so the product
    opinion is silently dropped: the intended override never happens.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel products = </Render/Proxy>
        }

        def RenderProduct "Proxy"
        {
            token productName = "proxy.exr"
            uniform token[] includedPurposes = ["default", "proxy"]
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
            uniform token[] includedPurposes = ["default", "proxy"]
            rel products = </Render/Proxy>
        }

        def RenderProduct "Proxy"
        {
            token productName = "proxy.exr"
        }
    }
    ```

    ## Fix safety
    No automatic fix: moving the opinion to the settings changes every other
    product of those settings; a separate RenderSettings is usually the right
    answer.
    """

    code = "PR007"
    name = "settings-only-attribute-on-product"
    severity = Severity.WARNING
    partial_composition = True
    prim_types = (schemas.RenderProduct,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        authored = prim_values(prim).authored_names()  # one call, not three a name
        for name in SETTINGS_ONLY_PROPERTIES:
            if name not in authored:
                continue
            prop = prim.GetProperty(name)
            yield Diagnostic(
                message=f"{name} is a RenderSettings property: on RenderProduct {prim.GetPath()} "
                "it is "
                "ignored by UsdRenderComputeSpec; author it on the RenderSettings (a separate "
                "RenderSettings if only this output needs it)",
                at=prop,
            )
