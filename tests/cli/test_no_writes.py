"""Nothing is written anywhere unless --fix, --fix-to, --output or
--write-baseline asks for it, but the result cache (in its own folder at the
project root; --no-cache: not even that): after plain runs the inputs' bytes and
modification times, and the folder listings, are exactly as before."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from click.testing import CliRunner
from pxr import Sdf, Usd, UsdRender, UsdUtils

from usdrender_lint.cli import cli

SHOT = """#usda 1.0
(
    subLayers = [@./layout.usda@]
)
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel camera = </World/Cam>
        uniform float4 dataWindowNDC = (1, 1, 0, 0)
        uniform bool instantaneousShutter = true
    }
}
"""
LAYOUT = """#usda 1.0
def Scope "World"
{
    def Camera "Cam"
    {
        float2 clippingRange = (10, 1)
    }
}
"""


def _snapshot(*folders: Path) -> dict[str, tuple[bytes | None, int]]:
    """Every path under the folders with its bytes (files) and mtime in ns."""
    state = {}
    for folder in folders:
        for root, dirs, names in os.walk(folder):
            for name in dirs + names:
                path = os.path.join(root, name)
                info = os.lstat(path)
                data = Path(path).read_bytes() if os.path.isfile(path) else None
                state[path] = (data, info.st_mtime_ns)
    return state


@pytest.fixture
def assets(tmp_path: Path) -> Path:
    """Text, crate and package layers with findings, a sublayer, a reference
    to a missing file and a broken file, so fixes and errors are on offer."""
    folder = tmp_path / "assets"
    folder.mkdir()
    (folder / "shot.usda").write_text(SHOT)
    (folder / "layout.usda").write_text(LAYOUT)
    (folder / "broken.usda").write_text('#usda 1.0\ndef Scope "X" {\n')
    (folder / "missing_ref.usda").write_text(
        '#usda 1.0\ndef RenderSettings "S" (\n    references = @./gone.usda@\n)\n{\n}\n'
    )
    layer = Sdf.Layer.CreateNew(str(folder / "crate.usdc"))
    stage = Usd.Stage.Open(layer)
    UsdRender.Settings.Define(stage, "/Render/S").CreatePixelAspectRatioAttr(-1.0)
    layer.Save()
    del stage
    UsdUtils.CreateNewUsdzPackage(str(folder / "shot.usda"), str(folder / "shot.usdz"))
    # Old mtimes: a rewrite within the same clock tick would still show.
    for path in folder.iterdir():
        os.utime(path, ns=(1_000_000_000, 1_000_000_000))
    return folder


@pytest.mark.parametrize(
    "options",
    [
        pytest.param(["--jobs", "1", "--timeout", "0"], id="in-process"),
        pytest.param(["--jobs", "2", "--format", "json", "--statistics"], id="workers-json"),
        pytest.param(["--jobs", "1", "--format", "sarif"], id="sarif"),
        pytest.param(["--jobs", "1", "--format", "github"], id="github"),
    ],
)
def test_a_plain_run_writes_nothing_but_its_result_cache(
    assets: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, options: list[str]
) -> None:
    workdir = tmp_path / "cwd"
    workdir.mkdir()
    monkeypatch.chdir(workdir)
    monkeypatch.delenv("USDRENDER_LINT_NO_CACHE", raising=False)
    before = _snapshot(assets, workdir)
    for extra in (["--no-cache"], []):
        result = CliRunner().invoke(cli, ["check", "--isolated", *options, *extra, str(assets)])
        assert result.exit_code == 1, result.stderr
        assert "ST001" in result.stdout and "SE003" in result.stdout
        if extra:
            assert _snapshot(assets, workdir) == before
    # The cache goes to the project root (the working directory without a
    # config file), in a folder of its own; the inputs are untouched.
    after = _snapshot(assets, workdir)
    cache = str(workdir / ".usdrender_lint_cache")
    assert {k: v for k, v in after.items() if not k.startswith(cache)} == before
    assert cache in after


def test_reading_a_baseline_writes_nothing(
    assets: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    baseline = tmp_path / "baseline.json"
    written = CliRunner().invoke(
        cli, ["check", "--isolated", "--jobs", "1", "--write-baseline", str(baseline), str(assets)]
    )
    assert written.exit_code == 0, written.stderr
    os.utime(baseline, ns=(1_000_000_000, 1_000_000_000))
    before = _snapshot(tmp_path)
    result = CliRunner().invoke(
        cli, ["check", "--isolated", "--jobs", "1", "--baseline", str(baseline), str(assets)]
    )
    assert result.exit_code == 0, result.stdout + result.stderr
    assert _snapshot(tmp_path) == before


def test_output_writes_only_the_report(
    assets: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    before = _snapshot(assets)
    report = tmp_path / "report.json"
    result = CliRunner().invoke(
        cli, ["check", "--isolated", "--format", "json", "--output", str(report), str(assets)]
    )
    assert result.exit_code == 1
    assert report.read_text().startswith("{")
    assert _snapshot(assets) == before
