"""The render specification as plain, immutable values (no pxr): what
:mod:`.compute` reads from a stage, what worker processes send back, and what
:mod:`.document` turns into the JSON document the views draw."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field
from typing import Any

from ..records import record
from .framing import Conformed, Pair, PixelWindow, Window

#: A time: a number, or None for ``Usd.TimeCode.Default()``.
Time = float | None


@record(frozen=True)
class Source:
    """Where a value comes from: ``kind`` is ``product``, ``settings``,
    ``camera`` or ``fallback`` (the schema's); ``path`` is the property that
    supplies it (the one a finding about the value is reported at)."""

    kind: str
    path: str | None
    layer: str | None = None
    line: int | None = None


@record(frozen=True)
class VarSpec:
    path: str
    name: str
    data_type: str
    source_name: str
    source_type: str
    namespaced_settings: Mapping[str, Any] = field(default_factory=dict)


@record(frozen=True)
class Framing:
    """The effective camera's aperture, read at the product's camera time,
    and what the conform policy made of it."""

    aperture: Pair
    offset: Pair
    conformed: Conformed
    screen_window: Window
    projection: str
    focal_length: float


@record(frozen=True)
class ComputeSpecView:
    """What ``UsdRenderComputeSpec`` itself gives for this product where it
    differs: it drops a product without a camera and reads the camera and
    productName at Default (``pxr/usd/usdRender/spec.cpp``)."""

    included: bool
    reason: str | None = None
    #: JSON field name -> the value UsdRenderComputeSpec gives instead.
    differs: Mapping[str, Any] = field(default_factory=dict)


@record(frozen=True)
class ProductSpec:
    """One product of a RenderSettings (or, with ``path`` None, the settings'
    own values, which its products inherit)."""

    path: str | None
    name: str | None
    type: str | None
    camera: str | None
    #: Why there is no usable camera, else None.
    camera_problem: str | None
    #: When the camera is one the renderer's application creates at run time
    #: (a profile's runtime camera, judged as CA003 and CA004 judge it): the
    #: profile and why; its values are not in the file. Else None.
    camera_at_run_time: tuple[str, str] | None
    #: The time the camera (and productName) were read at.
    time: Time
    #: The camera's rendered times (catalog R2-1).
    rendered_times: tuple[Time, ...]
    resolution: tuple[int, int]
    #: After the conform policy (adjustPixelAspectRatio changes it).
    pixel_aspect_ratio: float
    aspect_ratio_conform_policy: str
    framing: Framing | None
    data_window_ndc: Window
    data_window: PixelWindow | None
    disable_motion_blur: bool
    disable_depth_of_field: bool
    shutter: Pair | None
    vars: tuple[VarSpec, ...]
    namespaced_settings: Mapping[str, Any]
    #: JSON field (or camera attribute) name -> where the value comes from.
    sources: Mapping[str, Source]
    #: Prim paths whose findings concern this product.
    owners: tuple[str, ...]
    compute_spec: ComputeSpecView


@record(frozen=True)
class SettingsSpec:
    path: str
    primary: bool
    profile: str
    #: Why the profile was chosen (configured, or the evidence found).
    profile_reason: str
    included_purposes: tuple[str, ...]
    material_binding_purposes: tuple[str, ...]
    rendering_color_space: str | None
    namespaced_settings: Mapping[str, Any]
    sources: Mapping[str, Source]
    base: ProductSpec
    products: tuple[ProductSpec, ...]


@record(frozen=True)
class FileSpec:
    #: The time asked for and where it came from: ``--time``,
    #: ``startTimeCode`` or ``default``.
    time: Time
    time_from: str
    render_settings_prim_path: str | None
    settings: tuple[SettingsSpec, ...]
