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
    aperture = product["aperture"]
    camera = None
    image: Rect | None = None
    if aperture is not None and _finite(aperture["conformed"], aperture["offset"]):
        (w, h), (x, y) = aperture["conformed"], aperture["offset"]
        image = _drawable(Rect(x - w / 2, y - h / 2, x + w / 2, y + h / 2))
        if image is not None and _finite(aperture["camera"]):
            cw, ch = aperture["camera"]
            camera = _drawable(Rect(x - cw / 2, y - ch / 2, x + cw / 2, y + ch / 2))
    if image is None:
        # No camera, or an aperture that cannot be drawn: a zero aperture, or
        # an offset so large that the aperture vanishes beside it in floats.
        width, height = product["resolution"]
        aspect = (width / height) * (product["pixelAspectRatio"] or 1) if height > 0 else 1
        aspect = aspect if 0.05 < aspect < 20 else 1
        image = Rect(-aspect / 2, -0.5, aspect / 2, 0.5)
    ndc = product["dataWindowNDC"]
    window = product["dataWindow"]
    data = None
    overscan = cropped = False
    if _finite(ndc) and window is not None and window["width"] and window["height"]:
        xmin, ymin, xmax, ymax = ndc
        overscan = xmin < 0 or ymin < 0 or xmax > 1 or ymax > 1
        cropped = xmin > 0 or ymin > 0 or xmax < 1 or ymax < 1
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
            data = None  # far outside the image: not drawn (SE004 reports it)
    return Picture(image, camera, data, overscan, cropped)


def _drawable(rect: Rect) -> Rect | None:
    """``rect`` when it has a finite, positive size in floats, else None."""
    sizes = (rect.width, rect.height)
    return rect if all(math.isfinite(v) and v > 0 for v in sizes) else None


def _finite(*values: Any) -> bool:
    return all(v is not None for value in values for v in value)
