"""The Python the guides show runs as written, on the example broken shot
(the Houdini example needs Houdini: its ``hou`` is stood in for by a stage)."""

from __future__ import annotations

import re
import shutil
import types
from pathlib import Path

import pytest
from pxr import Usd

REPO = Path(__file__).resolve().parents[2]
GUIDES = REPO / "docs" / "guides"


def _blocks(page: str) -> list[str]:
    text = (GUIDES / page).read_text(encoding="utf-8")
    return re.findall(r"```python\n(.*?)```", text, re.DOTALL)


@pytest.fixture
def shot(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    for layer in (REPO / "examples" / "broken_shot").glob("*.usda"):
        shutil.copy(layer, tmp_path / layer.name)
    monkeypatch.chdir(tmp_path)
    return tmp_path / "shot.usda"


def test_the_python_api_examples_run(shot: Path, capsys: pytest.CaptureFixture[str]) -> None:
    lint_file, in_houdini = _blocks("python-api.md")[:2]
    exec(compile(lint_file, "python-api.md", "exec"), {})  # noqa: S102 - our own guide
    assert "CA004 " in capsys.readouterr().out
    node = types.SimpleNamespace(stage=lambda: Usd.Stage.Open(str(shot)), path=lambda: "/stage/rs")
    hou = types.SimpleNamespace(selectedNodes=lambda: [node])
    exec(  # noqa: S102 - our own guide
        compile(in_houdini.replace("import hou\n", ""), "python-api.md", "exec"), {"hou": hou}
    )
    assert "error   CA004 /Render/PrimarySettings.camera" in capsys.readouterr().out


def test_the_render_farm_preflight_example_stops_a_broken_shot(shot: Path) -> None:
    (preflight,) = _blocks("render-farm.md")
    with pytest.raises(SystemExit) as stopped:
        exec(compile(preflight, "render-farm.md", "exec"), {})  # noqa: S102 - our own guide
    assert "CA004 /Render/PrimarySettings.camera" in str(stopped.value)
