"""The working colour space, shared by SE012 and SE013: the authored
renderingColorSpace and one colour-space cache per lint."""

from __future__ import annotations

from pxr import Usd

from usdrender_lint.api import Context
from usdrender_lint.api.resolve import prim_values


def _rendering_color_space(prim: Usd.Prim) -> tuple[Usd.Attribute, str] | None:
    """The authored, non-empty renderingColorSpace (an empty token means unset)."""
    values = prim_values(prim)
    name = values.authored("renderingColorSpace")
    return (values.attribute("renderingColorSpace"), str(name)) if name else None


def _color_space_cache(ctx: Context) -> Usd.ColorSpaceCache:
    return ctx.cached(_new_color_space_cache)


def _new_color_space_cache(ctx: Context) -> Usd.ColorSpaceCache:
    return Usd.ColorSpaceCache()
