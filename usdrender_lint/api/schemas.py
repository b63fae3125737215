"""The schema types rules name, as ``Tf.Type`` handles.

``prim.IsA(schemas.RenderVar)``, ``prim_types = (schemas.RenderVar,)`` and
``ctx.prims_of(schemas.RenderVar)`` work without importing ``pxr.UsdRender``:
its Python bindings pull in UsdGeom's, UsdShade's and Sdr's, about a quarter
of a bare ``Usd.Stage.Open``'s whole process (issue 17, start-up). The C++
types are known from the plugins' ``plugInfo.json`` as soon as ``pxr.Usd`` is
loaded. The schema classes (``UsdRender.Var``) work wherever these do; use
them when a rule needs their API, imported where it is needed.
"""

from __future__ import annotations

from pxr import Tf


def _declared(name: str) -> Tf.Type:
    found = Tf.Type.FindByName(name)
    if found.isUnknown:  # a usd-core without the schema: fail at import, not per prim
        raise ImportError(f"usd-core declares no schema type {name}")
    return found


RenderSettingsBase = _declared("UsdRenderSettingsBase")
RenderSettings = _declared("UsdRenderSettings")
RenderProduct = _declared("UsdRenderProduct")
RenderVar = _declared("UsdRenderVar")
RenderPass = _declared("UsdRenderPass")
Camera = _declared("UsdGeomCamera")

#: UsdGeom's purposes in its order (``UsdGeomImageable::GetOrderedPurposeTokens``,
#: ``pxr/usd/usdGeom/imageable.cpp``), without importing UsdGeom.
ORDERED_PURPOSES = ("default", "render", "proxy", "guide")


def tf_type(schema: Tf.Type | type) -> Tf.Type:
    """The ``Tf.Type`` of a schema named either way."""
    return schema if isinstance(schema, Tf.Type) else Tf.Type.Find(schema)


__all__ = [
    "ORDERED_PURPOSES",
    "Camera",
    "RenderPass",
    "RenderProduct",
    "RenderSettings",
    "RenderSettingsBase",
    "RenderVar",
    "tf_type",
]
