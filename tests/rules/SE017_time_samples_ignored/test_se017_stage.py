"""SE017 through the engine, which tells it when no layer of the stage can
author time samples, a spline or value clips (their words): then it reads no
attribute. A layer that may hold them is still read, a crate's too."""

from __future__ import annotations

from pathlib import Path

import pytest
from pxr import Gf, Sdf, Usd, UsdRender

from usdrender_lint.api import resolve
from usdrender_lint.rules.settings.se017_time_samples_ignored import TimeSamplesIgnored
from usdrender_lint.testing import lint

STILL = (
    '#usda 1.0\ndef RenderSettings "S"\n{\n'
    "    uniform int2 resolution = (8, 8)\n"
    '    custom string note = "NOTE"\n}\n'
)


def _codes(path: Path) -> list[str]:
    return [f.code for f in lint(path, [TimeSamplesIgnored()])]


def test_se017_finds_the_samples_of_a_crate(tmp_path: Path) -> None:
    # A crate spells its fields in a token table of its own, compressed.
    path = tmp_path / "shot.usdc"
    stage = Usd.Stage.CreateNew(str(path))
    resolution = UsdRender.Settings.Define(stage, "/S").CreateResolutionAttr()
    resolution.Set(Gf.Vec2i(640, 480), 1)
    resolution.Set(Gf.Vec2i(1280, 960), 2)
    stage.Save()
    assert _codes(path) == ["SE017"]


def test_se017_finds_the_samples_of_a_crate_sublayer(tmp_path: Path) -> None:
    sublayer = Sdf.Layer.CreateNew(str(tmp_path / "animated.usdc"))
    stage = Usd.Stage.Open(sublayer)
    UsdRender.Settings.Define(stage, "/S").CreateResolutionAttr().Set(Gf.Vec2i(8, 8), 1)
    sublayer.Save()
    root = tmp_path / "shot.usda"
    root.write_text("#usda 1.0\n(\n    subLayers = [@./animated.usdc@]\n)\n")
    assert _codes(root) == ["SE017"]


@pytest.mark.parametrize(
    ("note", "read"),
    [("no such word", False), ("timeSamples", True), ("spline", True), ("clips", True)],
)
def test_se017_reads_attributes_only_where_a_layer_may_vary(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, note: str, read: bool
) -> None:
    # A word spelled in a string may be a field to the engine's scan: then the
    # attributes are read (and found still); without any, none is.
    asked: list[str] = []
    may_vary = resolve.PrimValues.may_vary

    def counting(values: resolve.PrimValues, name: str) -> bool:
        asked.append(name)
        return may_vary(values, name)

    monkeypatch.setattr(resolve.PrimValues, "may_vary", counting)
    path = tmp_path / "still.usda"
    path.write_text(STILL.replace("NOTE", note))
    assert _codes(path) == []
    assert bool(asked) is read
