"""The framing arithmetic of one render product, without USD: the aspect-ratio
conform policy, the conformed aperture's place in the camera's, the screen
window, and the pixels a data window keeps.

Each function follows one OpenUSD source (cited on it) operation for
operation, including its float precision, so that the numbers are the ones a
consumer of ``UsdRenderComputeSpec`` gets.
"""

from __future__ import annotations

import math
import struct

from ..api.raster import pixel_span
from ..records import record

EXPAND, CROP = "expandAperture", "cropAperture"
ADJUST_WIDTH, ADJUST_HEIGHT = "adjustApertureWidth", "adjustApertureHeight"
ADJUST_PIXEL_ASPECT = "adjustPixelAspectRatio"
#: ``GfCamera::APERTURE_UNIT``: apertures are in tenths of a scene unit.
APERTURE_UNIT = 0.1

Pair = tuple[float, float]
Window = tuple[float, float, float, float]


def f32(value: float) -> float:
    """``value`` rounded to a C++ ``float``. One operation on floats rounded
    this way is the float operation: a double holds every exact product or
    quotient of two floats closely enough to round it correctly."""
    if not math.isfinite(value):
        return value
    try:
        return float(struct.unpack("f", struct.pack("f", value))[0])
    except OverflowError:
        return math.copysign(math.inf, value)


@record(frozen=True)
class Conformed:
    """What ``_ApplyAspectRatioPolicy`` made of a product's aperture."""

    aperture: Pair
    pixel_aspect_ratio: float
    #: What the policy changed: "width" or "height" of the aperture, or
    #: "pixelAspectRatio"; None when nothing changed (the aspects already match).
    adjusted: str | None
    #: Why the policy was not applied (invalid inputs), else None.
    skipped: str | None = None


def apply_aspect_ratio_policy(
    resolution: tuple[int, int], pixel_aspect_ratio: float, aperture: Pair, policy: str
) -> Conformed:
    """The conformed aperture and pixel aspect ratio, as ``_ApplyAspectRatioPolicy``
    in ``pxr/usd/usdRender/spec.cpp`` computes them: in ``float``, the width or
    the height of the aperture changed so that its aspect equals the image's
    (``pixelAspectRatio * width / height``), or the pixel aspect ratio changed
    instead. Non-positive inputs leave everything as it is; an unknown policy
    token changes nothing (``skipped`` says why in both cases)."""
    width, height = resolution
    size = (f32(aperture[0]), f32(aperture[1]))
    pixel_aspect = f32(pixel_aspect_ratio)
    if width <= 0 or height <= 0 or size[0] <= 0 or size[1] <= 0:
        return Conformed(size, pixel_aspect, None, "a resolution or aperture size is not positive")
    resolution_aspect = f32(f32(width) / f32(height))
    image_aspect = f32(pixel_aspect * resolution_aspect)
    if image_aspect <= 0:
        return Conformed(size, pixel_aspect, None, "the image aspect ratio is not positive")
    aperture_aspect = f32(size[0] / size[1])
    if policy == ADJUST_PIXEL_ASPECT:
        adjusted = f32(aperture_aspect / resolution_aspect)
        return Conformed(size, adjusted, "pixelAspectRatio" if adjusted != pixel_aspect else None)
    adjust = _adjusted_side(policy, wider=aperture_aspect > image_aspect)
    if adjust is None:
        return Conformed(size, pixel_aspect, None, f"{policy!r} is not a conform policy")
    if adjust == "width":
        conformed = (f32(size[1] * image_aspect), size[1])
    else:
        conformed = (size[0], f32(size[0] / image_aspect))
    return Conformed(conformed, pixel_aspect, adjust if conformed != size else None)


def _adjusted_side(policy: str, *, wider: bool) -> str | None:
    """The side of the aperture ``policy`` changes (``wider``: the aperture is
    wider than the image); None for a token that is no such policy. Expanding
    grows the aperture to hold the image, cropping shrinks it to fit inside."""
    return {
        ADJUST_HEIGHT: "height",
        ADJUST_WIDTH: "width",
        EXPAND: "height" if wider else "width",
        CROP: "width" if wider else "height",
    }.get(policy)


def aperture_rectangle(size: Pair, offset: Pair) -> Window:
    """``(left, right, bottom, top)`` of an aperture of ``size`` whose centre
    is ``offset`` from the camera axis, in aperture units. A conformed aperture
    keeps the centre of the camera's (``CameraUtilConformedWindow`` on a
    ``GfRange2d``, ``pxr/imaging/cameraUtil/conformWindow.cpp``, conforms about
    the window's centre; ``_ApplyAspectRatioPolicy`` leaves the offsets alone)."""
    return (
        offset[0] - size[0] / 2,
        offset[0] + size[0] / 2,
        offset[1] - size[1] / 2,
        offset[1] + size[1] / 2,
    )


def screen_window(size: Pair, offset: Pair, projection: str) -> Window:
    """``(left, right, bottom, top)`` on the image plane, as
    ``CameraUtilScreenWindowParameters`` (``pxr/imaging/cameraUtil/
    screenWindowParameters.cpp``, horizontal fit, its default) computes it for a
    camera with this aperture and offset: ``-/+ aperture + 2 * offset`` in
    ``float``, then divided by the horizontal aperture for a perspective camera
    (the window is 2 wide), or scaled by ``APERTURE_UNIT / 2`` to scene units
    for an orthographic one."""
    h, v = f32(size[0]), f32(size[1])
    ho, vo = f32(offset[0]), f32(offset[1])
    window = (f32(2 * ho - h), f32(2 * ho + h), f32(2 * vo - v), f32(2 * vo + v))
    if projection == "orthographic":
        return tuple(c * (APERTURE_UNIT / 2.0) for c in window)  # type: ignore[return-value]
    if h != 0:
        return tuple(c / h for c in window)  # type: ignore[return-value]
    return window


@record(frozen=True)
class PixelWindow:
    """The pixels a data window keeps: ``first``..``last`` on each axis
    (inclusive; outside ``0..size-1`` in overscan). Rows count upwards from
    the bottom of the image, as NDC does."""

    x: tuple[int, int]
    y: tuple[int, int]
    #: The image height, to count rows from the top (image files do).
    image_height: int

    @property
    def width(self) -> int:
        return max(0, self.x[1] - self.x[0] + 1)

    @property
    def height(self) -> int:
        return max(0, self.y[1] - self.y[0] + 1)

    @property
    def empty(self) -> bool:
        return self.width == 0 or self.height == 0

    @property
    def y_from_top(self) -> tuple[int, int]:
        return self.image_height - 1 - self.y[1], self.image_height - 1 - self.y[0]


def data_window(ndc: Window, resolution: tuple[int, int]) -> PixelWindow | None:
    """The pixels whose centres ``dataWindowNDC`` (xmin, ymin, xmax, ymax)
    contains at ``resolution`` (the rasterization rule of
    ``pxr/usd/usdRender/overview.dox``: minimum edges included, maximum edges
    excluded); None when the resolution has no pixels or a bound is not finite."""
    width, height = resolution
    if width <= 0 or height <= 0 or not all(math.isfinite(c) for c in ndc):
        return None
    x0, x1 = pixel_span(ndc[0], ndc[2], width)
    y0, y1 = pixel_span(ndc[1], ndc[3], height)
    return PixelWindow((x0, x1 - 1), (y0, y1 - 1), height)
