"""stage.arcs_problem: what it reads before USD composes a stage."""

from __future__ import annotations

from pathlib import Path

import pytest
from pxr import Sdf

from usdrender_lint.engine import stage


def _no_resolver() -> None:
    raise AssertionError("a resolver context was made for a layer that names no layer")


def test_a_layer_naming_no_layer_is_not_walked(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    path = tmp_path / "shot.usda"
    path.write_text('#usda 1.0\ndef RenderSettings "Settings"\n{\n}\n')
    root = Sdf.Layer.FindOrOpen(str(path))
    monkeypatch.setattr(stage.Ar, "GetResolver", _no_resolver)
    assert stage.arcs_problem(root, str(path)) is None
    assert stage.arcs_problem(root, str(path), external=False) is None


def test_a_sublayer_is_still_read_and_held(tmp_path: Path) -> None:
    (tmp_path / "light.usda").write_text('#usda 1.0\ndef Scope "Light"\n{\n}\n')
    path = tmp_path / "shot.usda"
    path.write_text("#usda 1.0\n(\n    subLayers = [@light.usda@]\n)\n")
    held: list[Sdf.Layer] = []
    assert stage.arcs_problem(Sdf.Layer.FindOrOpen(str(path)), str(path), held=held) is None
    assert [Path(layer.realPath).name for layer in held] == ["light.usda"]
