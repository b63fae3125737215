"""What catalog Revision 2 changes in findings' messages: the first failing
rendered time as a number (R2-1), products rendered on their own named as such
(R2-4), and PR006 naming the settings two duplicate vars share (R2-3)."""

from __future__ import annotations

from pathlib import Path

import pytest

from usdrender_lint.testing import all_rules, lint

FIXTURES = Path(__file__).parent
RULES = all_rules()


def _messages(relative: str, code: str) -> dict[str, str]:
    return {
        f.location.path or "": f.message for f in lint(FIXTURES / relative, RULES) if f.code == code
    }


@pytest.mark.parametrize(
    ("folder", "code", "sublayer_path", "clip_path"),
    [
        (
            "CA005_camera_optics_invalid",
            "CA005",
            "/World/fromSublayer.focalLength",
            "/World/clipped.focalLength",
        ),
        (
            "CA006_aspect_ratio_mismatch_implicit_conform",
            "CA006",
            "/Render/fromSublayerSettings",
            "/Render/clippedSettings",
        ),
        (
            "CA007_depth_of_field_disabled_with_fstop",
            "CA007",
            "/Render/fromSublayerSettings.disableDepthOfField",
            "/Render/clippedSettings.disableDepthOfField",
        ),
        ("CA008_shutter_interval_inverted", "CA008", "/World/fromSublayer", "/World/clipped"),
        (
            "CA009_clipping_range_invalid",
            "CA009",
            "/World/fromSublayer.clippingRange",
            "/World/clipped.clippingRange",
        ),
    ],
)
def test_the_first_failing_rendered_time_is_named(
    folder: str, code: str, sublayer_path: str, clip_path: str
) -> None:
    messages = _messages(f"{folder}/fail_rendered_times.usda", code)
    # The sublayer's sample at 10, shifted by its offset 100; the clip's at stage time 10.
    assert "(at time 110)" in messages[sublayer_path]
    assert "(at time 10)" in messages[clip_path]


def test_houdini_apertures_are_read_at_the_rendered_frames() -> None:
    relative = "CA006_aspect_ratio_mismatch_implicit_conform/pass_samples_only_match.usda"
    assert _messages(relative, "CA006") == {}


def test_a_product_rendered_on_its_own_is_named_as_such() -> None:
    relative = "CA006_aspect_ratio_mismatch_implicit_conform/fail_product_on_its_own.usda"
    (message,) = _messages(relative, "CA006").values()
    assert message.startswith("product /Render/Orphan (rendered on its own): image aspect 1.778")
    assert "on </Render/Orphan>" in message


def test_st009_says_a_product_with_its_own_camera_is_checked_on_its_own() -> None:
    relative = "ST009_unreferenced_render_prim/fail_product_on_its_own.usda"
    (message,) = _messages(relative, "ST009").values()
    assert "render it on its own camera and values" in message
    orphans = _messages("ST009_unreferenced_render_prim/fail_orphans.usda", "ST009")
    assert "so nothing renders it" in orphans["/Render/Forgotten"]


def test_pr006_names_the_settings_both_vars_share() -> None:
    relative = "PR006_duplicate_render_vars/fail_same_settings_across_layers.usda"
    (message,) = _messages(relative, "PR006").values()
    assert "and the same arnold:filter, driver:parameters:aov:name," in message
