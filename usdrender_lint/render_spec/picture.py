"""The framing of one product as rectangles, for the text and SVG views:
the camera aperture, the image (the conformed aperture) and the data window,
in aperture units with y up, read from a product of the JSON document."""

from __future__ import annotations

import math
from typing import Any

from ..records import record

#: Overscan drawn at most this many image sizes beyond the image.
MAX_OVERSCAN = 1.0


@record(frozen=True)
class Rect:
    left: float
    bottom: float
    right: float
    top: float

    @property
    def width(self) -> float:
        return self.right - self.left

    @property
    def height(self) -> float:
        return self.top - self.bottom

    def union(self, other: Rect) -> Rect:
        return Rect(
            min(self.left, other.left),
            min(self.bottom, other.bottom),
            max(self.right, other.right),
            max(self.top, other.top),
        )

    def clamp(self, bounds: Rect) -> Rect:
        return Rect(
            max(self.left, bounds.left),
            max(self.bottom, bounds.bottom),
            min(self.right, bounds.right),
            min(self.top, bounds.top),
        )


@record(frozen=True)
class Picture:
    """``camera`` is None without a usable camera (the image then has the
    image aspect and unit height); ``data`` is None when the data window keeps
    no pixel (or cannot be placed)."""

    image: Rect
    camera: Rect | None
    data: Rect | None
    overscan: bool
    cropped: bool

    @property
    def bounds(self) -> Rect:
        box = self.image
        for rect in (self.camera, self.data):
            if rect is not None:
                box = box.union(rect)
        return box


def picture(product: dict[str, Any]) -> Picture:
    image, camera = _apertures(product["aperture"])
    if image is None:
        # No camera, or an aperture that cannot be drawn: a zero aperture, or
        # an offset so large that the aperture vanishes beside it in floats.
        image = _image_of_resolution(product["resolution"], product["pixelAspectRatio"])
    ndc = product["dataWindowNDC"]
    window = product["dataWindow"]
    if not (_finite(ndc) and window is not None and window["width"] and window["height"]):
        return Picture(image, camera, None, False, False)
    xmin, ymin, xmax, ymax = ndc
    overscan = xmin < 0 or ymin < 0 or xmax > 1 or ymax > 1
    cropped = xmin > 0 or ymin > 0 or xmax < 1 or ymax < 1
    return Picture(image, camera, _data_window(image, ndc), overscan, cropped)


def _apertures(aperture: dict[str, Any] | None) -> tuple[Rect | None, Rect | None]:
    """The image (the conformed aperture) and the camera's aperture, each None
    when it cannot be drawn (the camera's also without an image)."""
    if aperture is None or not _finite(aperture["conformed"], aperture["offset"]):
        return None, None
    (w, h), (x, y) = aperture["conformed"], aperture["offset"]
    image = _drawable(Rect(x - w / 2, y - h / 2, x + w / 2, y + h / 2))
    if image is None or not _finite(aperture["camera"]):
        return image, None
    cw, ch = aperture["camera"]
    return image, _drawable(Rect(x - cw / 2, y - ch / 2, x + cw / 2, y + ch / 2))


def _image_of_resolution(resolution: list[int], pixel_aspect: float | None) -> Rect:
    """An image of unit height with the image's aspect (1 when it is absurd)."""
    width, height = resolution
    aspect = (width / height) * (pixel_aspect or 1) if height > 0 else 1
    aspect = aspect if 0.05 < aspect < 20 else 1
    return Rect(-aspect / 2, -0.5, aspect / 2, 0.5)


def _data_window(image: Rect, ndc: list[float]) -> Rect | None:
    """The data window placed on the image, overscan drawn up to MAX_OVERSCAN."""
    xmin, ymin, xmax, ymax = ndc
    margin = Rect(
        image.left - MAX_OVERSCAN * image.width,
        image.bottom - MAX_OVERSCAN * image.height,
        image.right + MAX_OVERSCAN * image.width,
        image.top + MAX_OVERSCAN * image.height,
    )
    data = Rect(
        image.left + xmin * image.width,
        image.bottom + ymin * image.height,
        image.left + xmax * image.width,
        image.bottom + ymax * image.height,
    ).clamp(margin)
    if data.width <= 0 or data.height <= 0:
        return None  # far outside the image: not drawn (SE004 reports it)
    return data


def _drawable(rect: Rect) -> Rect | None:
    """``rect`` when it has a finite, positive size in floats, else None."""
    sizes = (rect.width, rect.height)
    return rect if all(math.isfinite(v) and v > 0 for v in sizes) else None


def _finite(*values: Any) -> bool:
    return all(v is not None for value in values for v in value)
