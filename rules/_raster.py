"""Raster arithmetic shared by the data-window and aspect rules."""

from __future__ import annotations

import math


def pixel_centres(lo: float, hi: float, size: int) -> int:
    """How many pixel centres ``(i + 0.5) / size`` lie in ``[lo, hi)``.

    The rasterization rule of ``pxr/usd/usdRender/overview.dox``: centres on the
    minimum edge are included, centres on the maximum edge excluded. The window
    may extend past the aperture (overscan), so centres are not clamped to it.
    """
    if size <= 0:
        return 0
    return max(0, math.ceil(hi * size - 0.5) - math.ceil(lo * size - 0.5))
