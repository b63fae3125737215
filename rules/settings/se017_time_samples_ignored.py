"""SE017 time-samples-ignored."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, schemas
from usdrender_lint.api.resolve import DEFAULT_TIME, time_samples

from ._fixes import Apply
from ._messages import _fmt
from ._schema_attributes import _RENDER_PRIM_TYPES, _authored_schema_attributes

#: Where a value comes from when the attribute has time samples or a spline
#: (GetResolveInfo() without a time: samples beat a default of the same layer).
_VARYING_SOURCES = frozenset(
    {
        Usd.ResolveInfoSourceTimeSamples,
        Usd.ResolveInfoSourceValueClips,
        Usd.ResolveInfoSourceSpline,
    }
)


def _first_sampled_layer(attr: Usd.Attribute) -> Sdf.Layer | None:
    """The layer whose time samples supply the attribute's value."""
    for spec in attr.GetPropertyStack(DEFAULT_TIME):
        if spec.layer.GetNumTimeSamplesForPath(spec.path):
            return spec.layer
    return None


def _samples_to_default(attr_path: Sdf.Path, value: Any) -> Apply:
    def apply(stage: Usd.Stage) -> None:
        attr = stage.GetAttributeAtPath(attr_path)
        attr.Clear()  # default and samples in the edit target
        attr.Set(value)

    return apply


def _renderer_reads(behaviour: Any, attr: Usd.Attribute) -> str:
    """The clause saying how the profile's renderer reads the attribute, and
    what is left: tools that read the default time."""
    return (
        f": {behaviour.what}; tools that read the default time, as UsdRenderComputeSpec does, "
        f"get {_fmt(attr.Get())}"
    )


class TimeSamplesIgnored(Rule):
    """A uniform render attribute has time samples, which spec-based consumers ignore.

    ## What it does
    Reports (a) a schema attribute of a render prim that the schema declares
    `uniform` but that has time samples or a spline, and (b) a RenderProduct's
    `productName`, the only varying render attribute, that has time samples but
    no default value.

    ## Why is this bad?
    Every usdRender setting is declared `uniform`
    (`pxr/usd/usdRender/schema.usda`) and `UsdRenderComputeSpec` reads them at
    `UsdTimeCode::Default()` (`pxr/usd/usdRender/spec.cpp`). With only samples
    authored, the Default read returns the **fallback** (resolution
    (2048, 1080)) while frame reads return the samples, and because the
    attribute counts as authored, a product override made only of samples
    replaces the settings value with the product's fallback. USD does not
    enforce `uniform`: *"Variability is a statement of intent but doesn't
    control behavior"* (`pxr/usd/usd/stage.cpp`). A renderer may read them at
    the frame it renders all the same: under the `karma` and `arnold`
    profiles the finding is info and says so, as husk and arnold-usd read the
    render prims at each rendered frame and follow the samples; tools reading
    the default time still get the fallback.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform int2 resolution.timeSamples = {
                1001: (1920, 1080),
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
            uniform int2 resolution = (1920, 1080)
        }
    }
    ```

    ## Fix safety
    Safe, conditional: for a uniform attribute whose samples all hold the same
    value (and whose default, if any, equals it), the fix replaces them with
    that default value in the layer holding the samples. Varying samples and
    `productName` are not fixed.
    """

    code = "SE017"
    name = "time-samples-ignored"
    severity = Severity.WARNING
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = _RENDER_PRIM_TYPES

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        if ctx.cache.nothing_varies:
            return
        values, declared = _authored_schema_attributes(prim)
        for name, schema in declared:
            # Both findings need samples or a spline, which few attributes have:
            # the opinions already read say so for most (may_vary), else the
            # value's source in one call (the count and HasSpline() are two),
            # before the dearer type check.
            if not values.may_vary(name):
                continue
            attr = values.attribute(name)
            if attr.GetResolveInfo().GetSource() not in _VARYING_SOURCES:
                continue
            count = attr.GetNumTimeSamples()
            if (not count and not attr.HasSpline()) or values.mismatched(name) is not None:
                continue  # nothing to report, or SE016's finding
            if schema.uniform:
                yield from self._uniform(attr, count, ctx)
            elif name == "productName" and prim.IsA(schemas.RenderProduct):
                yield from self._product_name(attr, count, ctx)

    def _uniform(self, attr: Usd.Attribute, count: int, ctx: Context) -> Iterator[Diagnostic]:
        behaviour = ctx.behaviour(self.code, attr)
        if attr.HasSpline():
            read = (
                f", but renderers read it once at the default time (getting {_fmt(attr.Get())})"
                if behaviour is None
                else _renderer_reads(behaviour, attr)
            )
            yield Diagnostic(
                message=f"uniform {attr.GetName()} is authored as a spline{read}; author a single "
                "default value instead",
                at=attr,
            )
            return
        if count == 0:
            return
        first = time_samples(attr, 1)[0]
        times = time_samples(attr, ctx.time_sample_cap)
        values = [attr.Get(t) for t in times]
        layer = _first_sampled_layer(attr)
        default_spec = next(
            (s for s in attr.GetPropertyStack(DEFAULT_TIME) if s.layer == layer), None
        )
        default = default_spec.default if default_spec and default_spec.HasDefaultValue() else None
        fix = None
        uniform_value = len(times) == count and all(v == values[0] for v in values)
        if uniform_value and default in (None, values[0]):
            fix = Fix(
                description=f"replace the samples with the default value {_fmt(values[0])}",
                safe=True,
                apply=_samples_to_default(attr.GetPath(), values[0]),
            )
        shown = (
            _fmt(values[0]) if uniform_value else f"{len(set(map(str, values)))} distinct values"
        )
        read = (
            f", but renderers read it once at the default time and get {_fmt(attr.Get())}"
            if behaviour is None
            else _renderer_reads(behaviour, attr)
        )
        yield Diagnostic(
            message=f"uniform {attr.GetName()} has {count} time sample(s) ({shown}) from "
            f"{first:g}{read}; author one default value instead of time samples",
            at=attr,
            fix=fix,
            layer=layer,
        )

    def _product_name(self, attr: Usd.Attribute, count: int, ctx: Context) -> Iterator[Diagnostic]:
        if count == 0:
            return
        source = attr.GetResolveInfo(DEFAULT_TIME).GetSource()
        if source == Usd.ResolveInfoSourceDefault:
            return
        first = time_samples(attr, 1)[0]
        behaviour = ctx.behaviour(self.code, attr)
        read = (
            f", so consumers reading at the default time get {_fmt(attr.Get())}"
            if behaviour is None
            else _renderer_reads(behaviour, attr)
        )
        yield Diagnostic(
            message=f"productName has time samples (first {_fmt(attr.Get(first))} at {first:g}) "
            f"but no default{read}; author a default productName as well",
            at=attr,
            layer=_first_sampled_layer(attr),
        )
