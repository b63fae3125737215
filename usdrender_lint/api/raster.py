"""Raster arithmetic shared by the data-window rules and `spec`: the pixels a window keeps."""

from __future__ import annotations

import math


def pixel_span(lo: float, hi: float, size: int) -> tuple[int, int]:
    """The pixels ``[first, end)`` whose centres ``(i + 0.5) / size`` lie in ``[lo, hi)``.

    The rasterization rule of ``pxr/usd/usdRender/overview.dox``: centres on the
    minimum edge are included, centres on the maximum edge excluded. The window
    may extend past the aperture (overscan), so indices are not clamped to
    ``[0, size)``.
    """
    return math.ceil(lo * size - 0.5), math.ceil(hi * size - 0.5)


def pixel_centres(lo: float, hi: float, size: int) -> int:
    """How many pixel centres lie in ``[lo, hi)`` at ``size`` pixels (see pixel_span)."""
    if size <= 0:
        return 0
    first, end = pixel_span(lo, hi, size)
    return max(0, end - first)
