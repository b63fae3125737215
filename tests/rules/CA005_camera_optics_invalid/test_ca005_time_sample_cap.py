"""CA005 evaluates camera values over time samples up to the linter's cap."""

from __future__ import annotations

from pathlib import Path

from usdrender_lint.engine import Linter
from usdrender_lint.rules.camera.ca005_camera_optics_invalid import CameraOpticsInvalid


def _lint_text(tmp_path: Path, text: str, cap: int) -> list[str]:
    path = tmp_path / "shot.usda"
    path.write_text(text, encoding="utf-8")
    linter = Linter([CameraOpticsInvalid()], time_sample_cap=cap, raise_errors=True)
    return [f.message for f in linter.lint_path(str(path)).findings]


def test_ca005_time_samples_beyond_the_cap_are_not_read(tmp_path: Path) -> None:
    text = """#usda 1.0
def Camera "cam"
{
    float focalLength.timeSamples = {
        1: 35,
        2: 40,
        3: 0,
    }
}
def RenderSettings "Settings"
{
    rel camera = </cam>
}
"""
    assert _lint_text(tmp_path, text, cap=2) == []
    (message,) = _lint_text(tmp_path, text, cap=3)
    assert "focalLength is 0" in message and "time 3" in message
