"""resolve.joint_evaluation_times: the default time, then the merged, sorted
time samples of several attributes, up to the cap."""

from __future__ import annotations

from rule_support import stage_from_text

from usdrender_lint.api.resolve import joint_evaluation_times


def test_joint_evaluation_times_merge_sort_and_cap() -> None:
    stage = stage_from_text(
        """#usda 1.0
def Camera "cam"
{
    double shutter:open.timeSamples = { 5: 0, 1: 0 }
    double shutter:close.timeSamples = { 3: 1, 5: 1, 9: 1 }
}
"""
    )
    camera = stage.GetPrimAtPath("/cam")
    attrs = [camera.GetAttribute("shutter:open"), camera.GetAttribute("shutter:close")]
    times = list(joint_evaluation_times(attrs, cap=3))
    assert times[0].IsDefault()
    assert [t.GetValue() for t in times[1:]] == [1.0, 3.0, 5.0]
