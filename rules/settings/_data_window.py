"""Authored dataWindowNDC values and the resolutions they render at, shared by
the data-window rules (SE003, SE004, SE005)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from usdrender_lint.api import Context, record, schemas
from usdrender_lint.api.raster import pixel_centres
from usdrender_lint.api.resolve import EffectiveValue, is_finite, items, prim_values

from .._camera import config_authors
from ._messages import _fmt

_WINDOW = "dataWindowNDC"


def _data_window_problem(window, resolution) -> str | None:
    """Why an authored dataWindowNDC renders nothing sensible, or None."""
    components = items(window)
    xmin, ymin, xmax, ymax = (float(c) for c in components)
    if not is_finite(components):
        return "has a NaN or infinite component"
    if xmin >= xmax or ymin >= ymax:
        axis = "x" if xmin >= xmax else "y"
        return f"is inverted or empty on {axis} (min must be < max)"
    width, height = int(resolution[0]), int(resolution[1])
    if (
        width > 0
        and height > 0
        and (pixel_centres(xmin, xmax, width) == 0 or pixel_centres(ymin, ymax, height) == 0)
    ):
        return f"contains no pixel centre at resolution {width}x{height}"
    return None


@record(frozen=True)
class _WindowUse:
    """An authored dataWindowNDC and a resolution it is rendered at."""

    window: EffectiveValue
    resolution: Any

    @property
    def values(self) -> tuple[float, float, float, float]:
        xmin, ymin, xmax, ymax = (float(c) for c in items(self.window.value))
        return xmin, ymin, xmax, ymax

    @property
    def text(self) -> str:
        return _fmt(tuple(round(c, 6) for c in self.values))


def _window_uses(ctx: Context) -> list[_WindowUse]:
    """Every authored dataWindowNDC with the resolution of each configuration
    it is used in: a product's window or resolution overrides the settings'
    (catalog SE003: checked once per settings that targets the product); a
    product rendered on its own uses its own values and the fallbacks (R2-4)."""
    return ctx.cached(_find_window_uses)


def _find_window_uses(ctx: Context) -> list[_WindowUse]:
    uses = []
    # (window attribute, resolution) of each use: a window rendered at one
    # resolution is one use, however many configurations render it (the
    # products of a settings that inherit its window and resolution), and
    # each data-window rule reports it once, not once per product.
    found = set()
    for config in ctx.configurations:
        # Whether the window is authored, asked of the prims' values (once per
        # lint): most configurations author none and need no effective values.
        if not config_authors(config, _WINDOW):
            continue
        window = config.effective(_WINDOW)  # the resolution is read only for a window to check
        resolution = config.effective("resolution").value
        key = (window.attr.GetPath(), tuple(items(resolution)))
        if key not in found:
            found.add(key)
            uses.append(_WindowUse(window, resolution))
    # Each settings' own window at its own resolution (even when every product
    # overrides it), and untargeted products whether or not they render on
    # their own; a use already found above is not listed twice.
    for prim in (*ctx.prims_of(schemas.RenderSettings), *ctx.untargeted_products):
        values = prim_values(prim)
        # By name: the values' own answers, not a second read of the opinions.
        if values.has_value(_WINDOW):
            attr = values.attribute(_WINDOW)
            resolution = values.composed("resolution")
            if (attr.GetPath(), tuple(items(resolution))) not in found:
                window = EffectiveValue(values.authored(_WINDOW), attr, True)
                uses.append(_WindowUse(window, resolution))
    return uses


def _well_formed_window_uses(ctx: Context) -> Iterator[_WindowUse]:
    """The uses SE003 accepts: SE004 and SE005 only look at those."""
    for use in _window_uses(ctx):
        if _data_window_problem(use.window.value, use.resolution) is None:
            yield use
