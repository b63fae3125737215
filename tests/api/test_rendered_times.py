"""rendered_times: the times a renderer reads varying camera inputs at
(catalog Revision 2, R2-1)."""

from __future__ import annotations

from pathlib import Path

from pxr import Sdf, Usd

from usdrender_lint.api.resolve import rendered_times


def _stage(text: str) -> Usd.Stage:
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(text)
    return Usd.Stage.Open(layer)


def _times(stage: Usd.Stage, *names: str, cap: int = 1000) -> list[float | None]:
    camera = stage.GetPrimAtPath("/cam")
    times = rendered_times([camera.GetAttribute(n) for n in names], cap)
    return [None if t.IsDefault() else t.GetValue() for t in times]


def test_default_only_when_no_attribute_has_samples() -> None:
    stage = _stage('#usda 1.0\ndef Camera "cam"\n{\n    float horizontalAperture = 36\n}\n')
    # An authored default, an unauthored attribute, a missing attribute: all Default.
    assert _times(stage, "horizontalAperture", "verticalAperture", "noSuchAttr") == [None]
    assert rendered_times([], cap=10) == [Usd.TimeCode.Default()]


def test_all_sample_times_without_a_range_and_default_is_not_rendered() -> None:
    stage = _stage(
        """#usda 1.0
def Camera "cam"
{
    float horizontalAperture = 20
    float horizontalAperture.timeSamples = { 175: 0.00045365, 176: 0.00045365 }
    float verticalAperture.timeSamples = { 176: 0.00025518, 180: 1 }
}
"""
    )
    assert _times(stage, "horizontalAperture", "verticalAperture") == [175.0, 176.0, 180.0]
    # Only the attributes the check reads count.
    assert _times(stage, "verticalAperture") == [176.0, 180.0]


def test_samples_inside_the_authored_range_plus_both_ends() -> None:
    stage = _stage(
        """#usda 1.0
(
    startTimeCode = 100
    endTimeCode = 120
)
def Camera "cam"
{
    float focalLength.timeSamples = { 90: 1, 105: 2, 110: 3, 130: 4 }
}
"""
    )
    assert _times(stage, "focalLength") == [100.0, 105.0, 110.0, 120.0]


def test_samples_outside_the_range_give_its_ends() -> None:
    stage = _stage(
        """#usda 1.0
(
    startTimeCode = 100
    endTimeCode = 120
)
def Camera "cam"
{
    float focalLength.timeSamples = { 1: 1, 10: 0 }
}
"""
    )
    # Frames 100..120 render the value held from time 10.
    assert _times(stage, "focalLength") == [100.0, 120.0]


def test_a_range_with_only_one_end_authored_is_no_range() -> None:
    stage = _stage(
        """#usda 1.0
(
    startTimeCode = 100
)
def Camera "cam"
{
    float focalLength.timeSamples = { 1: 1, 10: 0 }
}
"""
    )
    assert _times(stage, "focalLength") == [1.0, 10.0]


def test_cap_limits_the_total() -> None:
    stage = _stage(
        """#usda 1.0
def Camera "cam"
{
    double shutter:open.timeSamples = { 5: 0, 1: 0 }
    double shutter:close.timeSamples = { 3: 1, 5: 1, 9: 1 }
}
"""
    )
    assert _times(stage, "shutter:open", "shutter:close", cap=3) == [1.0, 3.0, 5.0]


def test_type_mismatched_samples_are_not_rendered_times() -> None:
    stage = _stage(
        """#usda 1.0
def Camera "cam"
{
    float2 focalLength.timeSamples = { 1: (1, 2) }
}
"""
    )
    assert _times(stage, "focalLength") == [None]


def test_sublayer_samples_with_offset_and_a_range_in_a_weaker_layer(tmp_path: Path) -> None:
    (tmp_path / "anim.usda").write_text(
        """#usda 1.0
(
    startTimeCode = 1000
    endTimeCode = 1001
)
over "cam"
{
    float focalLength.timeSamples = { 10: 35, 20: 50 }
}
"""
    )
    (tmp_path / "shot.usda").write_text(
        """#usda 1.0
(
    subLayers = [@anim.usda@ (offset = 5)]
)
def Camera "cam"
{
}
"""
    )
    stage = Usd.Stage.Open(str(tmp_path / "shot.usda"))
    # Stage times (offset applied); the sublayer's range is not the stage's.
    assert _times(stage, "focalLength") == [15.0, 25.0]


def test_value_clip_samples_are_rendered_times(tmp_path: Path) -> None:
    (tmp_path / "clip.usda").write_text(
        """#usda 1.0
def Camera "cam"
{
    float focalLength.timeSamples = { 0: 35, 1: 50 }
}
"""
    )
    (tmp_path / "shot.usda").write_text(
        """#usda 1.0
(
    startTimeCode = 101
    endTimeCode = 102
)
def Camera "cam" (
    clips = {
        dictionary default = {
            asset[] assetPaths = [@./clip.usda@]
            string primPath = "/cam"
            double2[] active = [(101, 0)]
            double2[] times = [(101, 0), (102, 1)]
        }
    }
)
{
}
"""
    )
    stage = Usd.Stage.Open(str(tmp_path / "shot.usda"))
    # The clip's samples, mapped to stage times by `times`.
    assert _times(stage, "focalLength") == [101.0, 102.0]
