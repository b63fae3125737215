"""The framing arithmetic against hand-computed values: every conform policy
with the aperture wider and narrower than the image, non-square pixels, the
float precision of spec.cpp, the screen window, the data window's pixels."""

from __future__ import annotations

import pytest

from usdrender_lint.render_spec.framing import (
    PixelWindow,
    apply_aspect_ratio_policy,
    data_window,
    f32,
    screen_window,
)

HD = (1920, 1080)
WIDE = (40.0, 20.0)  # aspect 2.0, wider than 16:9
NARROW = (36.0, 24.0)  # aspect 1.5, narrower than 16:9


@pytest.mark.parametrize(
    ("policy", "aperture", "conformed", "adjusted"),
    [
        # Expand keeps the whole aperture: the short side grows.
        ("expandAperture", WIDE, (40.0, 40 * 1080 / 1920), "height"),  # 22.5
        ("expandAperture", NARROW, (24 * 1920 / 1080, 24.0), "width"),  # 42.667
        # Crop keeps the image filled: the long side shrinks.
        ("cropAperture", WIDE, (20 * 1920 / 1080, 20.0), "width"),  # 35.556
        ("cropAperture", NARROW, (36.0, 36 * 1080 / 1920), "height"),  # 20.25
        # The named side changes, whichever way round.
        ("adjustApertureWidth", WIDE, (20 * 1920 / 1080, 20.0), "width"),
        ("adjustApertureWidth", NARROW, (24 * 1920 / 1080, 24.0), "width"),
        ("adjustApertureHeight", WIDE, (40.0, 40 * 1080 / 1920), "height"),
        ("adjustApertureHeight", NARROW, (36.0, 36 * 1080 / 1920), "height"),
    ],
)
def test_aperture_policies_both_ways_round(
    policy: str, aperture: tuple[float, float], conformed: tuple[float, float], adjusted: str
) -> None:
    result = apply_aspect_ratio_policy(HD, 1.0, aperture, policy)
    assert result.aperture == pytest.approx(conformed, rel=1e-6)
    assert result.aperture[0] / result.aperture[1] == pytest.approx(1920 / 1080, rel=1e-6)
    assert result.pixel_aspect_ratio == 1.0
    assert result.adjusted == adjusted
    assert result.skipped is None


@pytest.mark.parametrize(
    ("aperture", "pixel_aspect"),
    [(WIDE, 2.0 * 1080 / 1920), (NARROW, 1.5 * 1080 / 1920)],  # 1.125 and 0.84375
)
def test_adjust_pixel_aspect_ratio_keeps_the_aperture(
    aperture: tuple[float, float], pixel_aspect: float
) -> None:
    result = apply_aspect_ratio_policy(HD, 1.0, aperture, "adjustPixelAspectRatio")
    assert result.aperture == aperture
    assert result.pixel_aspect_ratio == pytest.approx(pixel_aspect, rel=1e-6)
    assert result.adjusted == "pixelAspectRatio"


def test_the_arithmetic_is_spec_cpps_float_arithmetic() -> None:
    # 24 * f32(1920 / 1080) in float is 42.66666793823242, not the double 42.666666...
    result = apply_aspect_ratio_policy(HD, 1.0, NARROW, "expandAperture")
    assert result.aperture[0] == f32(24 * f32(1920 / 1080)) == 42.66666793823242
    assert result.aperture[0] != 24 * 1920 / 1080


def test_non_square_pixels_enter_the_image_aspect() -> None:
    # 960x1080 with 2:1 pixels is a 16:9 image: a 36x24 aperture widens to 42.667.
    result = apply_aspect_ratio_policy((960, 1080), 2.0, NARROW, "expandAperture")
    assert result.aperture == pytest.approx((24 * 16 / 9, 24.0), rel=1e-6)
    assert result.pixel_aspect_ratio == 2.0
    # adjustPixelAspectRatio: the pixels take the aperture's aspect over the resolution's.
    result = apply_aspect_ratio_policy((960, 1080), 2.0, NARROW, "adjustPixelAspectRatio")
    assert result.pixel_aspect_ratio == pytest.approx(1.5 / (960 / 1080), rel=1e-6)  # 1.6875


def test_matching_aspects_change_nothing() -> None:
    result = apply_aspect_ratio_policy(HD, 1.0, (36.0, 20.25), "expandAperture")
    assert result.aperture == (36.0, 20.25)
    assert result.adjusted is None


@pytest.mark.parametrize(
    ("resolution", "pixel_aspect", "aperture", "policy", "why"),
    [
        ((0, 1080), 1.0, NARROW, "expandAperture", "not positive"),
        (HD, 1.0, (0.0, 24.0), "expandAperture", "not positive"),
        (HD, -1.0, NARROW, "expandAperture", "image aspect ratio is not positive"),
        (HD, 1.0, NARROW, "stretch", "'stretch' is not a conform policy"),
    ],
)
def test_invalid_inputs_and_unknown_policies_conform_nothing(
    resolution: tuple[int, int],
    pixel_aspect: float,
    aperture: tuple[float, float],
    policy: str,
    why: str,
) -> None:
    result = apply_aspect_ratio_policy(resolution, pixel_aspect, aperture, policy)
    assert result.aperture == aperture
    assert result.pixel_aspect_ratio == pixel_aspect
    assert result.adjusted is None
    assert why in result.skipped


def test_screen_window_of_a_perspective_camera_is_two_wide() -> None:
    window = screen_window((36.0, 20.25), (0.0, 0.0), "perspective")
    assert window == (-1.0, 1.0, -0.5625, 0.5625)


def test_screen_window_moves_with_the_aperture_offset() -> None:
    # (-36 + 2*2) / 36, (36 + 2*2) / 36, (-20.25 - 2) / 36, (20.25 - 2) / 36
    window = screen_window((36.0, 20.25), (2.0, -1.0), "perspective")
    assert window == pytest.approx((-32 / 36, 40 / 36, -22.25 / 36, 18.25 / 36))


def test_screen_window_of_an_orthographic_camera_is_in_scene_units() -> None:
    # Apertures are tenths of a scene unit: 36 wide is 3.6 units, -1.8 .. 1.8.
    window = screen_window((36.0, 20.25), (0.0, 0.0), "orthographic")
    assert window == pytest.approx((-1.8, 1.8, -1.0125, 1.0125))


def test_full_data_window_keeps_every_pixel() -> None:
    window = data_window((0.0, 0.0, 1.0, 1.0), HD)
    assert (window.x, window.y, window.width, window.height) == ((0, 1919), (0, 1079), 1920, 1080)
    assert window.y_from_top == (0, 1079)


def test_crop_keeps_the_pixels_whose_centres_it_contains() -> None:
    window = data_window((0.25, 0.25, 0.75, 0.75), HD)
    # x: centres (i + 0.5) / 1920 in [0.25, 0.75): i = 480 .. 1439.
    assert (window.x, window.y, window.width, window.height) == (
        (480, 1439),
        (270, 809),
        960,
        540,
    )


def test_rows_count_up_from_the_bottom_and_down_from_the_top() -> None:
    window = data_window((0.0, 0.0, 0.5, 0.25), HD)  # the bottom-left of the image
    assert window.y == (0, 269)
    assert window.y_from_top == (810, 1079)


def test_minimum_edges_are_included_and_maximum_edges_excluded() -> None:
    # 4 pixels: centres at 0.125, 0.375, 0.625, 0.875. [0.125, 0.375) holds pixel 0 only.
    window = data_window((0.125, 0.125, 0.375, 0.375), (4, 4))
    assert window.x == (0, 0) and window.y == (0, 0)


def test_overscan_gives_negative_firsts() -> None:
    window = data_window((-0.05, -0.05, 1.05, 1.05), HD)
    assert (window.x, window.y, window.width, window.height) == (
        (-96, 2015),
        (-54, 1133),
        2112,
        1188,
    )


def test_an_inverted_window_is_empty() -> None:
    window = data_window((0.75, 0.25, 0.25, 0.75), HD)
    assert window.width == 0 and window.height == 540
    assert window.empty


def test_no_pixels_without_a_resolution() -> None:
    assert data_window((0.0, 0.0, 1.0, 1.0), (0, 1080)) is None
    assert data_window((float("nan"), 0.0, 1.0, 1.0), HD) is None
    assert not PixelWindow((0, 0), (0, 0), 1).empty
