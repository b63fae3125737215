"""The Python the guides show runs as written, on the example broken shot
(the Houdini example needs Houdini: its ``hou`` is stood in for by a stage)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
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


def _run_with_the_usd_plugin(code: str, cwd: Path) -> str:
    """``code`` in a process whose USD finds the UsdValidation plugin (USD reads
    PXR_PLUGINPATH_NAME once, when its plugin registry starts)."""
    from usdrender_lint.usdplugin import plugin_dir

    env = dict(os.environ, PXR_PLUGINPATH_NAME=str(plugin_dir()))
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=cwd, env=env, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return done.stdout


def test_the_usdvalidation_example_prints_each_errors_prim_or_property(shot: Path) -> None:
    (validate,) = _blocks("usdvalidation.md")
    printed = _run_with_the_usd_plugin(validate, shot.parent).splitlines()
    assert any(line.startswith("CA004 /Render/PrimarySettings.camera ") for line in printed)
    assert any(line.startswith("PR004 /Render/Products/utility ") for line in printed)


def test_the_usdvalidation_fixer_example_makes_the_edit_the_guide_shows(shot: Path) -> None:
    fix = _blocks("asset-validator.md")[1]
    before = shot.read_text(encoding="utf-8")
    _run_with_the_usd_plugin(fix, shot.parent)
    changed = [
        (old, new)
        for old, new in zip(
            before.splitlines(), shot.read_text(encoding="utf-8").splitlines(), strict=True
        )
        if old != new
    ]
    assert changed == [
        ("        rel camera = </World/camRig>", "        rel camera = </World/camRig/shotCam>")
    ]
