"""SE rule options (SE001 require-authored, SE013 flag-data-spaces) and the
shared colour-space and raster helpers the family uses."""

from __future__ import annotations

from pathlib import Path

import pytest
from pxr import Usd
from usdrender_lint.rules import _colorspace, _raster
from usdrender_lint.rules.settings.se001_resolution_non_positive import ResolutionNonPositive
from usdrender_lint.rules.settings.se013_rendering_color_space_not_linear import (
    RenderingColorSpaceNotLinear,
)

from usdrender_lint.config import ConfigError, Settings
from usdrender_lint.engine import Linter
from usdrender_lint.registry import build_registry
from usdrender_lint.running.pipeline import make_rules

UNAUTHORED_RESOLUTION = """#usda 1.0
def RenderSettings "S"
{
}
"""
RAW_SPACE = """#usda 1.0
def RenderSettings "S"
{
    uniform token renderingColorSpace = "raw"
}
"""


def _codes(tmp_path: Path, text: str, settings: Settings, code: str) -> list[str]:
    path = tmp_path / "stage.usda"
    path.write_text(text, encoding="utf-8")
    rules = [r for r in make_rules_for(settings) if r.code == code]
    result = Linter(rules, raise_errors=True).lint_path(str(path))
    return [f.location.path for f in result.findings if f.code == code]


def make_rules_for(settings: Settings):
    return make_rules(build_registry(), settings)


@pytest.mark.parametrize(
    ("rule", "option", "text", "code"),
    [
        ("resolution-non-positive", "require-authored", UNAUTHORED_RESOLUTION, "SE001"),
        ("SE013", "flag-data-spaces", RAW_SPACE, "SE013"),
    ],
)
def test_option_is_off_by_default_and_reports_when_set(
    tmp_path: Path, rule: str, option: str, text: str, code: str
) -> None:
    assert _codes(tmp_path, text, Settings(), code) == []
    settings = Settings(rule_options={rule: {option: True}})
    assert len(_codes(tmp_path, text, settings, code)) == 1


@pytest.mark.parametrize(
    "options",
    [
        {"require-authored": "yes"},  # mistyped
        {"require_authored": 1},  # mistyped
        {"require-authorized": True},  # unknown
    ],
)
def test_bad_se001_option_is_a_config_error(options: dict) -> None:
    with pytest.raises(ConfigError, match="resolution-non-positive"):
        make_rules_for(Settings(rule_options={"resolution-non-positive": options}))


def test_bad_se013_option_is_a_config_error() -> None:
    with pytest.raises(ConfigError, match="unknown option 'strict'"):
        make_rules_for(Settings(rule_options={"SE013": {"strict": True}}))


def test_options_defaults() -> None:
    assert ResolutionNonPositive().options.require_authored is False
    assert RenderingColorSpaceNotLinear().options.flag_data_spaces is False


# -- helpers ---------------------------------------------------------------------


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
