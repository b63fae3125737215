"""The colour-space and raster helpers the SE rules share (rules/_colorspace.py,
usdrender_lint/api/raster.py)."""

from __future__ import annotations

import pytest
from pxr import Usd

from usdrender_lint.api import raster as _raster
from usdrender_lint.rules import _colorspace


def test_canonical_names_are_the_26_11_tokens() -> None:
    assert "lin_p3d65_scene" in _colorspace.CANONICAL_NAMES
    assert "lin_displayp3_scene" not in _colorspace.CANONICAL_NAMES  # the 24.11 name
    assert len(_colorspace.CANONICAL_NAMES) == len(set(_colorspace.CANONICAL_NAMES)) == 19


@pytest.mark.parametrize(
    ("name", "first"),
    [("ACES - ACEScg", "lin_ap1_scene"), ("lin_rec709", "lin_rec709_scene")],
)
def test_nearest_names(name: str, first: str) -> None:
    assert _colorspace.nearest_names(name)[0] == first


@pytest.mark.parametrize(
    ("encoded", "linear"),
    [
        ("srgb_rec709_scene", "lin_rec709_scene"),
        ("g22_ap1_scene", "lin_ap1_scene"),
        ("srgb_p3d65_scene", "lin_p3d65_scene"),
    ],
)
def test_linear_counterpart_has_the_same_primaries(encoded: str, linear: str) -> None:
    stage = Usd.Stage.CreateInMemory()
    prim = stage.DefinePrim("/S", "RenderSettings")
    space = _colorspace.resolve(prim, encoded, Usd.ColorSpaceCache())
    assert space is not None and not space.is_linear
    assert _colorspace.linear_counterpart(space) == linear


@pytest.mark.parametrize(
    ("lo", "hi", "size", "span"),
    [
        (0.0, 1.0, 10, (0, 10)),
        (0.05, 0.15, 10, (0, 1)),  # min edge on a centre: included; max edge: excluded
        (-0.1, 1.1, 10, (-1, 11)),  # overscan is not clamped
        (0.06, 0.14, 10, (1, 1)),  # between two centres: empty
    ],
)
def test_pixel_span(lo: float, hi: float, size: int, span: tuple[int, int]) -> None:
    assert _raster.pixel_span(lo, hi, size) == span
    assert _raster.pixel_centres(lo, hi, size) == span[1] - span[0]
