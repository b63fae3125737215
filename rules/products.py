"""PR: RenderProduct checks."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass

from pxr import Sdf, Usd, UsdRender

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity
from usdrender_lint.resolve import (
    allowed_tokens,
    authored_targets,
    authored_value,
    composed_value,
    describe_prim_type,
    format_time,
    forwarded_targets,
    joint_evaluation_times,
    mismatched_spec,
    resolve_target,
)

from ._aov import checked_value, ordered_var_targets, product_render_vars
from ._corrections import set_value, unique_case_match


class ProductNameEmpty(Rule):
    """A RenderProduct's productName is empty.

    ## What it does
    Reports a usable RenderProduct whose `productName` (a varying `token`,
    fallback `""`) is `""` at the default time and has no time samples: left
    unauthored, authored empty, or blocked. A productName authored only as
    time samples is SE017's case, and a type-mismatched opinion SE016's.

    ## Why is this bad?
    *"Specifies the name that the output/display driver should give the
    product."* (`pxr/usd/usdRender/schema.usda`); *"e.g. using the productName
    for the filename (and path) for an output image artifact"*
    (`RenderProduct.md`). An empty name gives the display driver nothing to
    write to: renderers either fail or invent a name.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            rel orderedVars = </Render/Vars/color>
        }

        def Scope "Vars"
        {
            def RenderVar "color"
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
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = </Render/Vars/color>
        }

        def Scope "Vars"
        {
            def RenderVar "color"
            {
                string sourceName = "Ci"
            }
        }
    }
    ```

    ## Fix safety
    Safe, conditional: only when the pipeline configures a naming template
    (option `name-template`, e.g. `"{prim}.exr"`) does the fix author the
    name it gives; by default there is no fix, the output name being a
    pipeline decision. (The catalog's class: none, pipeline template.)

    ## Options
    `name-template` (string, default empty: no fix): the productName the fix
    authors; `{prim}` is replaced by the product's prim name.
    """

    code = "PR001"
    name = "product-name-empty"
    severity = Severity.ERROR
    fix_safety = "safe-conditional"
    prim_types = (UsdRender.Product,)

    @dataclass(frozen=True)
    class Options:
        name_template: str = ""

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("productName")
        if attr.GetNumTimeSamples():
            return
        if checked_value(prim, "productName", ctx) != "":
            return
        if attr.GetResolveInfo().ValueIsBlocked():
            how = "is blocked"
        else:
            how = "is authored empty" if attr.HasAuthoredValue() else "has no authored value"
        template = self.options.name_template
        fix = None
        if template:
            name = template.replace("{prim}", prim.GetName())
            fix = Fix(f"author productName = {name!r}", True, set_value(attr.GetPath(), name))
        yield Diagnostic(
            f"RenderProduct {prim.GetPath()} has an empty productName (it {how}): the display "
            f"driver has no name to write to; author one, e.g. token productName = "
            f'"{prim.GetName()}.exr"',
            at=attr if attr.IsAuthored() else prim,
            fix=fix,
        )


def _product_name(product: Usd.Prim, time: Usd.TimeCode) -> str:
    """productName at ``time``: authored, else the fallback; "" when mistyped."""
    attr = product.GetAttribute("productName")
    if mismatched_spec(attr) is not None:
        return ""
    return composed_value(product, "productName", time) or ""


class ProductNameDuplicate(Rule):
    """Two products of one RenderSettings have the same productName.

    ## What it does
    For each RenderSettings, compares the `productName` of the usable
    RenderProducts its `products` targets (forwarded), at the default time and
    at every time where any of them has a time sample (capped). Two different
    products with the same non-empty name are reported once, on the second,
    at the first time they collide.

    ## Why is this bad?
    `productName` is *"used by render executables and pipeline tools to name
    the product, for example, using the productName as the filename (and
    path) for an output image artifact"* (RenderProduct prim definition,
    usd-core 26.11). Two products of one render writing the same file clobber
    each other.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel products = [</Render/Beauty>, </Render/Utility>]
        }

        def RenderProduct "Beauty"
        {
            token productName = "shot.exr"
        }

        def RenderProduct "Utility"
        {
            token productName = "shot.exr"
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
            rel products = [</Render/Beauty>, </Render/Utility>]
        }

        def RenderProduct "Beauty"
        {
            token productName = "shot_beauty.exr"
        }

        def RenderProduct "Utility"
        {
            token productName = "shot_utility.exr"
        }
    }
    ```

    ## Fix safety
    No automatic fix: which product should be renamed, and to what, is the
    author's choice.
    """

    code = "PR002"
    name = "product-name-duplicate"
    severity = Severity.ERROR

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        reported: set[tuple[Sdf.Path, Sdf.Path]] = set()
        # The configurations already pair each settings with its usable products, in order.
        products_of: dict[Sdf.Path, list[Usd.Prim]] = {}
        for config in ctx.configurations:
            products = products_of.setdefault(config.settings.GetPath(), [])
            if config.product is not None:
                products.append(config.product)
        for settings in ctx.prims_of(UsdRender.Settings):
            products = products_of[settings.GetPath()]
            attrs = [p.GetAttribute("productName") for p in products]
            for time in joint_evaluation_times(attrs, ctx.time_sample_cap):
                owners: dict[str, Usd.Prim] = {}
                for product in products:
                    name = _product_name(product, time)
                    first = owners.setdefault(name, product)
                    if not name or first == product:
                        continue
                    # Paths are built only for a duplicate.
                    pair = (first.GetPath(), product.GetPath())
                    if pair in reported:
                        continue
                    reported.add(pair)
                    yield Diagnostic(
                        f"RenderProduct {product.GetPath()} has productName {name!r} at "
                        f"{format_time(time)}, like {first.GetPath()}: both are products of "
                        f"{settings.GetPath()} and write the same output; give each product "
                        "its own productName",
                        at=product.GetAttribute("productName"),
                    )


def _renderer_product_type(prim: Usd.Prim) -> str | None:
    """An authored ``<renderer>:productType`` override, the schema-sanctioned
    way to ask for a custom output type (catalog, Ambiguous semantics 14)."""
    for attr in prim.GetAuthoredAttributes():
        if attr.GetName().endswith(":productType") and attr.HasAuthoredValue():
            return attr.GetName()
    return None


class ProductTypeNotAllowed(Rule):
    """A RenderProduct's productType is not raster or deepRaster.

    ## What it does
    Reports an authored `productType` that is not one of the schema's
    `allowedTokens` (`raster`, `deepRaster`), unless the product also has an
    authored renderer-specific override attribute whose name ends in
    `:productType` (e.g. `ri:productType`).

    ## Why is this bad?
    `allowedTokens = ["raster", "deepRaster"]` and *"Renderers that support
    custom output types are encouraged to supply an applied API schema that
    will add an `token myRenderContext:productType` attribute (e.g. `token
    ri:productType`), which will override this attribute's value for that
    renderer."* (`pxr/usd/usdRender/schema.usda`). A file format such as `exr`
    in `productType` is a common confusion with `productName`.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            uniform token productType = "exr"
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
            token productName = "beauty.exr"
            uniform token productType = "raster"
        }
    }
    ```

    ## Fix safety
    Safe, conditional: a value that differs from an allowed token only in case
    (`DeepRaster`) is corrected to it (`deepRaster`); otherwise there is no
    fix.
    """

    code = "PR003"
    name = "product-type-not-allowed"
    severity = Severity.WARNING
    fix_safety = "safe-conditional"
    prim_types = (UsdRender.Product,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("productType")
        value = authored_value(attr)
        allowed = allowed_tokens(prim, "productType")
        if value is None or value in allowed or _renderer_product_type(prim):
            return
        correction = unique_case_match(value, allowed)
        if correction:
            advice = f"did you mean {correction!r}?"
        else:
            advice = (
                f"use {' or '.join(allowed)} (a file format belongs in productName), or author "
                "a renderer-specific override such as ri:productType"
            )
        yield Diagnostic(
            f"productType {value!r} of {prim.GetPath()} is not one of {', '.join(allowed)}; "
            + advice,
            at=attr,
            fix=Fix(
                f"set productType to {correction!r}", True, set_value(attr.GetPath(), correction)
            )
            if correction
            else None,
        )


class ProductMissingRenderVars(Rule):
    """A RenderProduct has no RenderVars in orderedVars.

    ## What it does
    Reports every usable RenderProduct, targeted by a RenderSettings or not,
    whose `orderedVars` has no forwarded target: the relationship is
    unauthored, authored empty, or emptied by list-op composition.

    ## Why is this bad?
    *"If products are provided, the products should be explicit about which
    RenderVars are needed."* (`RenderSettings.md`); *"A RenderProduct must also
    specify one or more RenderVars"* (`pxr/usd/usdRender/userDoc/overview.md`).
    The product reaches the renderer with zero channels: at best an empty file.

    ## Example
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
            rel orderedVars = [</Render/Vars/color>, </Render/Vars/alpha>]
        }

        def Scope "Vars"
        {
            def RenderVar "color"
            {
                string sourceName = "Ci"
            }

            def RenderVar "alpha"
            {
                token dataType = "float"
                string sourceName = "a"
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: which outputs a product needs is a pipeline decision.
    """

    code = "PR004"
    name = "product-missing-render-vars"
    severity = Severity.ERROR
    prim_types = (UsdRender.Product,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        rel = prim.GetRelationship("orderedVars")
        if forwarded_targets(rel):
            return
        state = "is empty" if rel and rel.HasAuthoredTargets() else "is not authored"
        yield Diagnostic(
            f"RenderProduct {prim.GetPath()} has no RenderVars: orderedVars {state}; target "
            "the RenderVars this output needs, e.g. rel orderedVars = [</Render/Vars/color>]",
            at=rel if rel and rel.HasAuthoredTargets() else prim,
        )


def _remove_target(rel_path: Sdf.Path, target: Sdf.Path) -> Callable[[Usd.Stage], None]:
    def apply(stage: Usd.Stage) -> None:
        stage.GetRelationshipAtPath(rel_path).RemoveTarget(target)

    return apply


def _append_target(rel_path: Sdf.Path, target: Sdf.Path) -> Callable[[Usd.Stage], None]:
    def apply(stage: Usd.Stage) -> None:
        stage.GetRelationshipAtPath(rel_path).AddTarget(target, Usd.ListPositionBackOfAppendList)

    return apply


class OrderedVarsInvalidTarget(Rule):
    """An orderedVars target is not a usable RenderVar.

    ## What it does
    Checks each forwarded `orderedVars` target of a usable RenderProduct and
    reports one that is not a prim path, has no prim on the composed stage, is
    not usable (inactive, only an `over`, or abstract) or is not a RenderVar;
    the message says which.

    ## Why is this bad?
    *"Specifies the RenderVars that should be consumed and combined into the
    final product."* (`pxr/usd/usdRender/schema.usda`). spec.cpp: *"Render
    product <%s> includes render var at path <%s>, but no suitable UsdRenderVar
    prim was found. Skipping."* (`pxr/usd/usdRender/spec.cpp`): the channel
    silently disappears from the output.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = [</Render/Vars/color>, </Render/Vars/diffuse>]
        }

        def Scope "Vars"
        {
            def RenderVar "color"
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
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = </Render/Vars/color>
        }

        def Scope "Vars"
        {
            def RenderVar "color"
            {
                string sourceName = "Ci"
            }
        }
    }
    ```

    ## Fix safety
    Unsafe: the fix removes the bad target from `orderedVars` (when this
    relationship authors it rather than forwarding it), which changes the
    product's channel list; the author may instead have meant another path.
    """

    code = "PR005"
    name = "ordered-vars-invalid-target"
    severity = Severity.ERROR
    fix_safety = "unsafe"
    prim_types = (UsdRender.Product,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        rel = prim.GetRelationship("orderedVars")
        authored = set(authored_targets(rel))
        for target in ordered_var_targets(prim, ctx):
            if target.prim is None:
                reason = target.problem
            elif not target.prim.IsA(UsdRender.Var):
                reason = f"is {describe_prim_type(target.prim)}, not a RenderVar"
                if target.problem:
                    reason += f", and {target.problem}"
            elif target.problem:
                reason = f"is a RenderVar but {target.problem}"
            else:
                continue
            fix = None
            if target.path in authored:
                fix = Fix(
                    f"remove <{target.path}> from orderedVars",
                    False,
                    _remove_target(rel.GetPath(), target.path),
                )
            yield Diagnostic(
                f"orderedVars target <{target.path}> of {prim.GetPath()} {reason}: the channel "
                "is silently missing from the output; target a defined, active RenderVar or "
                "remove the target",
                at=rel,
                fix=fix,
            )


class DuplicateRenderVars(Rule):
    """Two RenderVars of one product compute the same source.

    ## What it does
    Reports two different usable RenderVar prims targeted by the same
    product's `orderedVars` whose composed `(sourceType, sourceName, dataType)`
    are identical. (The same path twice cannot occur: usd-core rejects duplicate
    targets in one list-op at parse time, and composed list-ops de-duplicate.)
    A var with an empty `sourceName` is left to VA001.

    ## Why is this bad?
    Each RenderVar is *"a quantity or 'channel' of computed data"* (RenderVar
    prim definition, usd-core 26.11): two vars computing the same source
    produce a redundant channel, and, in renderers that name channels after
    `sourceName` for non-LPE vars (hdPrman's `_ComputeRenderViewDesc`,
    `third_party/renderman-26/plugin/hdPrman/renderParam.cpp`), a channel-name
    clash.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = [</Render/Vars/color>, </Render/Vars/beauty>]
        }

        def Scope "Vars"
        {
            def RenderVar "color"
            {
                string sourceName = "Ci"
            }

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
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = [</Render/Vars/color>, </Render/Vars/alpha>]
        }

        def Scope "Vars"
        {
            def RenderVar "color"
            {
                string sourceName = "Ci"
            }

            def RenderVar "alpha"
            {
                token dataType = "float"
                string sourceName = "a"
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: which var to keep (and under which channel name) is the
    author's choice.
    """

    code = "PR006"
    name = "duplicate-render-vars"
    severity = Severity.WARNING
    prim_types = (UsdRender.Product,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        seen: dict[tuple, Usd.Prim] = {}
        for var in product_render_vars(prim, ctx):
            key = tuple(
                checked_value(var, n, ctx) for n in ("sourceType", "sourceName", "dataType")
            )
            if None in key or not key[1]:
                continue
            first = seen.setdefault(key, var)
            if first == var:  # the same prim (Usd.Prim equality), without building paths
                continue
            source_type, source_name, data_type = key
            yield Diagnostic(
                f"RenderVars {first.GetPath()} and {var.GetPath()} of {prim.GetPath()} both "
                f"compute sourceType {source_type!r}, sourceName {source_name!r}, dataType "
                f"{data_type!r}: a redundant channel; remove one from orderedVars or change "
                "its source",
                at=UsdRender.Product(prim).GetOrderedVarsRel(),
            )


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
    prim_types = (UsdRender.Product,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        for name in SETTINGS_ONLY_PROPERTIES:
            prop = prim.GetProperty(name)
            if not prop or not prop.IsAuthored():
                continue
            yield Diagnostic(
                f"{name} is a RenderSettings property: on RenderProduct {prim.GetPath()} it is "
                "ignored by UsdRenderComputeSpec; author it on the RenderSettings (a separate "
                "RenderSettings if only this output needs it)",
                at=prop,
            )


ALPHA_NAMES = frozenset({"a", "alpha"})
FOUR_CHANNEL_TYPES = frozenset({"color4f", "color4h", "color4d", "float4", "half4", "double4"})


def _is_alpha_source(var: Usd.Prim, ctx: Context) -> bool:
    source = checked_value(var, "sourceName", ctx) or ""
    return (
        var.GetName().lower() in ALPHA_NAMES
        or source.lower() in ALPHA_NAMES
        or checked_value(var, "dataType", ctx) in FOUR_CHANNEL_TYPES
    )


class DeepRasterMissingAlpha(Rule):
    """A deepRaster product has no alpha RenderVar.

    ## What it does
    Reports a usable RenderProduct whose composed `productType` is
    `deepRaster`, that has at least one valid RenderVar, and none of whose
    RenderVars is an alpha source: no var whose prim name or `sourceName` is
    `a` or `alpha` (any case) and none with a 4-channel `dataType`
    (`color4f/color4h/color4d/float4/half4/double4`).

    ## Why is this bad?
    *"Every color or auxiliary channel in a deep image must have an associated
    alpha channel."* (OpenEXR, `website/InterpretingDeepPixels.rst`). Z is
    normally emitted by the deep display driver itself; alpha must be
    requested as a RenderVar, otherwise deep merge and flatten cannot
    composite the samples.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Deep"
        {
            token productName = "deep.exr"
            uniform token productType = "deepRaster"
            rel orderedVars = </Render/Vars/color>
        }

        def Scope "Vars"
        {
            def RenderVar "color"
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
        def RenderProduct "Deep"
        {
            token productName = "deep.exr"
            uniform token productType = "deepRaster"
            rel orderedVars = [</Render/Vars/color>, </Render/Vars/alpha>]
        }

        def Scope "Vars"
        {
            def RenderVar "color"
            {
                string sourceName = "Ci"
            }

            def RenderVar "alpha"
            {
                token dataType = "float"
                string sourceName = "a"
            }
        }
    }
    ```

    ## Fix safety
    Safe, conditional: only when the pipeline configures its default alpha
    RenderVar (option `alpha-var`, a prim path) and that prim is a usable
    alpha RenderVar on the stage does the fix append it to `orderedVars`; by
    default there is no fix. (The catalog's class: none, pipeline default
    vars.)

    ## Options
    `alpha-var` (prim path, default empty: no fix): the RenderVar the fix
    appends, e.g. `"/Render/Vars/alpha"`.
    """

    code = "PR008"
    name = "deep-raster-missing-alpha"
    severity = Severity.WARNING
    fix_safety = "safe-conditional"
    prim_types = (UsdRender.Product,)

    @dataclass(frozen=True)
    class Options:
        alpha_var: str = ""

    def _alpha_fix(self, product: Usd.Prim, ctx: Context) -> Fix | None:
        path = self.options.alpha_var
        if not path or not Sdf.Path.IsValidPathString(path):
            return None
        target = resolve_target(product.GetStage(), Sdf.Path(path))
        if not target.ok or not target.prim.IsA(UsdRender.Var):
            return None
        if not _is_alpha_source(target.prim, ctx):
            return None
        rel_path = product.GetRelationship("orderedVars").GetPath()
        return Fix(f"append <{path}> to orderedVars", True, _append_target(rel_path, target.path))

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        if checked_value(prim, "productType", ctx) != "deepRaster":
            return
        render_vars = product_render_vars(prim, ctx)
        if not render_vars or any(_is_alpha_source(v, ctx) for v in render_vars):
            return
        yield Diagnostic(
            f"deep RenderProduct {prim.GetPath()} has no alpha RenderVar (none named a or alpha "
            "by prim name or sourceName, none with a 4-channel dataType): deep samples cannot "
            'be composited; add a RenderVar with sourceName "a" and dataType "float" to '
            "orderedVars",
            at=prim,
            fix=self._alpha_fix(prim, ctx),
        )


RULES = (
    ProductNameEmpty,
    ProductNameDuplicate,
    ProductTypeNotAllowed,
    ProductMissingRenderVars,
    OrderedVarsInvalidTarget,
    DuplicateRenderVars,
    SettingsOnlyAttributeOnProduct,
    DeepRasterMissingAlpha,
)
