"""Helpers the command-line tests share: the command in its own process, a
small crate layer to corrupt, and a layer naming a variant \"\"."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from pxr import Gf, Sdf, Usd, UsdGeom, UsdRender

#: A RenderSettings whose variant set holds a variant named "": Sdf's walks of
#: such a layer abort or recurse without end (usd-core 26.11); composing it works.
EMPTY_VARIANT_NAME = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings" (
        variantSets = "quality"
    )
    {
        variantSet "quality" = {
            "" {
                rel camera = </World/cam>
            }
        }
    }
}
"""


def run_cli_process(folder: Path, *args: str) -> subprocess.CompletedProcess:
    """The command in its own process, for inputs that make USD abort: USD
    writes a crash report to its temporary folder, which here is ``folder``."""
    crash_reports = folder / "usd-crash-reports"
    crash_reports.mkdir(exist_ok=True)
    result = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "--format", "json", *args],
        capture_output=True,
        text=True,
        env={**os.environ, "TMPDIR": str(crash_reports)},
        timeout=600,
    )
    assert "Traceback" not in result.stdout + result.stderr, result.stderr
    return result


def settings_crate(path: Path) -> bytes:
    """A small crate layer with settings, product, var and camera (also fuzzed)."""
    layer = Sdf.Layer.CreateNew(str(path))
    stage = Usd.Stage.Open(layer)
    settings = UsdRender.Settings.Define(stage, "/Render/S")
    settings.CreateResolutionAttr(Gf.Vec2i(1920, 1080))
    settings.CreateDataWindowNDCAttr(Gf.Vec4f(0, 0, 1, 1))
    settings.GetCameraRel().SetTargets(["/World/Cam"])
    product = UsdRender.Product.Define(stage, "/Render/P")
    product.CreateProductNameAttr("a.exr")
    settings.GetProductsRel().SetTargets(["/Render/P"])
    var = UsdRender.Var.Define(stage, "/Render/V")
    var.CreateSourceNameAttr("Ci")
    product.GetOrderedVarsRel().SetTargets(["/Render/V"])
    UsdGeom.Camera.Define(stage, "/World/Cam").CreateFocalLengthAttr(35)
    layer.Save()
    return path.read_bytes()
