"""SE016 attribute-type-mismatch."""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity

from ._fixes import Apply
from ._schema_attributes import _RENDER_PRIM_TYPES, _authored_schema_attributes

_NOT_CONVERTIBLE = object()


def _convert_scalar(value: Any, like: Any) -> Any:
    """``value`` as the Python type of ``like`` when no information is lost."""
    if isinstance(like, Sdf.AssetPath) and isinstance(value, str):
        return Sdf.AssetPath(value)  # a string path is an unresolved asset path
    if isinstance(like, bool):
        ok = isinstance(value, bool) or (isinstance(value, int) and value in (0, 1))
        return bool(value) if ok else _NOT_CONVERTIBLE
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        if isinstance(like, str) and isinstance(value, str):
            return str(value)  # string and token hold the same text
        return _NOT_CONVERTIBLE
    return _convert_number(value, like)


def _convert_number(value: int | float, like: Any) -> Any:
    """A number as the int or float type of ``like`` when no information is lost."""
    if isinstance(like, int):
        integral = math.isfinite(value) and float(value).is_integer()
        return int(value) if integral and abs(value) < 2**31 else _NOT_CONVERTIBLE
    if isinstance(like, float):
        # double -> float keeps the value within float precision (catalog SE016)
        return float(value) if not math.isfinite(value) or abs(value) < 3.4e38 else _NOT_CONVERTIBLE
    return _NOT_CONVERTIBLE


def _convert(value: Any, type_name: Sdf.ValueTypeName) -> Any:
    """``value`` re-typed as ``type_name`` when that is lossless, else _NOT_CONVERTIBLE."""
    like = type_name.defaultValue
    if type_name.isArray:
        if isinstance(value, str) or not hasattr(value, "__len__"):
            return _NOT_CONVERTIBLE
        items = [_convert(v, type_name.scalarType) for v in value]
        return _NOT_CONVERTIBLE if _NOT_CONVERTIBLE in items else type(like)(items)
    if isinstance(like, (bool, int, float, str, Sdf.AssetPath)):
        return _convert_scalar(value, like)
    if hasattr(like, "__len__") and hasattr(value, "__len__") and not isinstance(value, str):
        if len(value) != len(like):
            return _NOT_CONVERTIBLE
        items = [_convert_scalar(v, like[0]) for v in value]
        return _NOT_CONVERTIBLE if _NOT_CONVERTIBLE in items else type(like)(*items)
    return _NOT_CONVERTIBLE


def _spec_values(spec: Sdf.AttributeSpec) -> tuple[Any, dict[float, Any]]:
    """A spec's default (None when it has none) and its time samples."""
    default = spec.default if spec.HasDefaultValue() else None
    layer, path = spec.layer, spec.path
    samples = {t: layer.QueryTimeSample(path, t) for t in layer.ListTimeSamplesForPath(path)}
    return default, samples


def _retyped_values(
    spec: Sdf.AttributeSpec, type_name: Sdf.ValueTypeName
) -> tuple[Any, dict[float, Any]] | None:
    """The spec's default and samples converted to ``type_name``, or None when
    a value would not survive the conversion (value blocks are kept)."""
    default, samples = _spec_values(spec)
    new_default = _retyped(default, type_name)
    if new_default is _NOT_CONVERTIBLE:
        return None
    converted: dict[float, Any] = {}
    for time, value in samples.items():
        new = _retyped(value, type_name)
        if new is _NOT_CONVERTIBLE:
            return None
        converted[time] = new
    return new_default, converted


def _retyped(value: Any, type_name: Sdf.ValueTypeName) -> Any:
    """One value converted (None and value blocks kept), or _NOT_CONVERTIBLE."""
    if value is None or isinstance(value, Sdf.ValueBlock):
        return value
    return _convert(value, type_name)


#: The fields of a spec the re-authoring sets anew.
_RETYPED = frozenset({"typeName", "variability", "default", "timeSamples"})


def _retype_spec(attr_path: Sdf.Path, type_name: Sdf.ValueTypeName) -> Apply:
    """Re-author the edit target's spec of an attribute with the schema type."""

    def apply(stage: Usd.Stage) -> None:
        spec = stage.GetEditTarget().GetAttributeSpecForScenePath(attr_path)
        values = _retyped_values(spec, type_name) if spec else None
        if values is None:
            return
        default, samples = values
        owner, name, variability = spec.owner, spec.name, spec.variability
        # Its other fields (custom, connections, doc, customData...) stay as they were.
        kept = {key: spec.GetInfo(key) for key in spec.ListInfoKeys() if key not in _RETYPED}
        owner.RemoveProperty(spec)
        new = Sdf.AttributeSpec(owner, name, type_name, variability)
        for key, value in kept.items():
            if key == "connectionPaths":  # read-only to SetInfo: through its list editor
                _copy_list_op(new.connectionPathList, value)
            else:
                new.SetInfo(key, value)
        if default is not None:
            new.default = default
        for time, value in samples.items():
            new.layer.SetTimeSample(new.path, time, value)

    return apply


def _copy_list_op(editor: Any, op: Sdf.PathListOp) -> None:
    """Author ``op`` through a spec's list ``editor`` (e.g. ``connectionPathList``)."""
    if op.isExplicit:
        editor.ClearEditsAndMakeExplicit()
        editor.explicitItems = list(op.explicitItems)
        return
    editor.prependedItems = list(op.prependedItems)
    editor.appendedItems = list(op.appendedItems)
    editor.deletedItems = list(op.deletedItems)


class AttributeTypeMismatch(Rule):
    """A schema attribute of a render prim is authored with the wrong type.

    ## What it does
    For every authored attribute of a RenderSettings, RenderProduct, RenderVar
    or RenderPass whose name the prim definition declares, reports the
    strongest spec in the property stack whose type differs from the schema
    type (e.g. `float2 resolution`, `string productName`, `token sourceName`),
    as `usdValidation:AttributeTypeMismatch` does, even when a stronger
    well-typed opinion currently hides it. Every other rule treats such an
    opinion as unauthored, so one mistake gives one finding.

    ## Why is this bad?
    Schema types: `resolution` int2, `pixelAspectRatio` float, `dataWindowNDC`
    float4, `productName` token, `sourceName` string
    (`pxr/usd/usdRender/schema.usda`). A typed C++ read cannot store a
    mistyped value (`SdfAbstractDataTypedValue::StoreValue` sets
    `typeMismatch`, `pxr/usd/sdf/abstractData.h`), so C++ renderers lose the
    opinion without a diagnostic while Python tools see it.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform float2 resolution = (1920, 1080)
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
    Safe, conditional: when every value of the mistyped spec converts without
    loss (`float2 (1920, 1080)` to `int2`, `string` to `token`, `double4` to
    `float4` within float precision), the fix re-authors the spec with the
    schema type in the same layer, its other fields (connections, metadata)
    kept.
    """

    code = "SE016"
    name = "attribute-type-mismatch"
    severity = Severity.ERROR
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = _RENDER_PRIM_TYPES

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values, declared = _authored_schema_attributes(prim)
        for name, schema in declared:
            specs = values.mismatched_specs(name)
            if not specs:
                continue
            attr = values.attribute(name)
            schema_type = schema.type_name
            spec = specs[0]
            where = spec.layer.GetDisplayName()
            hidden = (
                ""
                if spec == values.mismatched(name)
                else (" (a stronger well-typed opinion hides it for now)")
            )
            fix = None
            if _retyped_values(spec, schema_type) is not None:
                fix = Fix(
                    description=f"re-author as {schema_type} in {where}",
                    safe=True,
                    apply=_retype_spec(attr.GetPath(), schema_type),
                )
            yield Diagnostic(
                message=f"{attr.GetName()} is authored as {spec.typeName} in {where}{hidden} but "
                "the "
                f"{prim.GetTypeName()} schema declares {schema_type}; C++ consumers drop "
                f"the value: author it as {schema_type}",
                at=attr,
                fix=fix,
                layer=spec.layer,
            )
