"""``spec`` judges a product's camera as ``check`` does (CA003, CA004) under
the profile its RenderSettings is judged under: a camera Kit creates at run
time (the omniverse profile's runtime cameras) is no problem and no flag; under
the generic profile the same camera is missing, flagged and reported."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli

#: A layer as Kit saves it: omni render settings and the viewport's bound
#: camera in customLayerData (the omniverse profile is inferred), and the
#: viewport's product targeting Kit's session camera, which the file does not hold.
KIT_LAYER = """#usda 1.0
(
    customLayerData = {
        dictionary cameraSettings = {
            string boundCamera = "/OmniverseKit_Persp"
        }
        dictionary renderSettings = {
            bool "rtx:post:tonemap:enabled" = 1
        }
    }
    startTimeCode = 0
)

def Xform "World"
{
}

def "Render"
{
    def RenderSettings "OmniverseGlobalRenderSettings"
    {
        token omni:rtx:rendermode = "RaytracedLighting"
        rel products = </Render/OmniverseKit/HydraTextures/Viewport>
    }

    def "OmniverseKit"
    {
        def "HydraTextures"
        {
            def RenderProduct "Viewport"
            {
                rel camera = </OmniverseKit_Persp>
                uniform int2 resolution = (1280, 720)
                rel orderedVars = </Render/Vars/LdrColor>
            }
        }
    }

    def "Vars"
    {
        def RenderVar "LdrColor"
        {
            uniform string sourceName = "LdrColor"
        }
    }
}
"""

#: The same product's camera as a `def Xform` where Kit's camera would be: judged (CA004).
KIT_XFORM = KIT_LAYER.replace('def Xform "World"', 'def Xform "OmniverseKit_Persp"')

PRODUCT = "/Render/OmniverseKit/HydraTextures/Viewport"


def invoke(*args: str):
    return CliRunner().invoke(cli, [*args[:1], "--isolated", "--jobs", "1", *args[1:]])


def product_json(path: Path, *options: str) -> dict:
    result = invoke("spec", "--format", "json", *options, str(path))
    assert result.exit_code == 0, result.output
    (settings,) = json.loads(result.stdout)["files"][0]["settings"]
    (product,) = settings["products"]
    assert product["path"] == PRODUCT
    return {"profile": settings["profile"], **product}


def check_codes(path: Path, *options: str) -> list[str]:
    result = invoke("check", "--no-cache", "--show-info", "--format", "json", *options, str(path))
    return [f["code"] for file in json.loads(result.stdout)["files"] for f in file["findings"]]


@pytest.fixture
def kit_layer(tmp_path: Path) -> Path:
    path = tmp_path / "kit_stage.usda"
    path.write_text(KIT_LAYER)
    return path


def test_a_kit_runtime_camera_is_no_problem_under_the_omniverse_profile(kit_layer: Path) -> None:
    assert not {"CA003", "CA004"} & set(check_codes(kit_layer))
    product = product_json(kit_layer)
    assert product["profile"] == "omniverse"
    assert product["camera"] == "/OmniverseKit_Persp"
    assert product["cameraProblem"] is None
    assert product["cameraAtRunTime"]["profile"] == "omniverse"
    assert "session layer" in product["cameraAtRunTime"]["why"]
    assert "camera" not in product["flags"]
    # Kit's camera values are not in the file: nothing is read or drawn for them.
    assert product["aperture"] is None and product["shutter"] is None

    text = invoke("spec", str(kit_layer)).stdout
    assert "/OmniverseKit_Persp  (created at run time: omniverse profile)" in text
    assert "does not exist" not in text and "no camera" not in text


def test_the_svg_does_not_draw_a_missing_camera(kit_layer: Path, tmp_path: Path) -> None:
    out = tmp_path / "svg"
    result = invoke("spec", "--format", "svg", "--output", str(out), str(kit_layer))
    assert result.exit_code == 0, result.output
    (svg,) = out.glob("*.svg")
    ElementTree.fromstring(svg.read_text())
    assert "no camera" not in svg.read_text() and "does not exist" not in svg.read_text()
    assert "created at run time" in svg.read_text()


def test_the_html_report_does_not_draw_a_missing_camera(kit_layer: Path, tmp_path: Path) -> None:
    out = tmp_path / "report.html"
    invoke("check", "--no-cache", "--format", "html", "--output", str(out), str(kit_layer))
    html = out.read_text()
    assert "created at run time" in html
    assert "no camera" not in html and "does not exist on the composed stage" not in html


def test_under_the_generic_profile_the_same_camera_is_missing(kit_layer: Path) -> None:
    assert "CA003" in check_codes(kit_layer, "--profile", "generic")
    product = product_json(kit_layer, "--profile", "generic")
    assert product["profile"] == "generic"
    assert product["cameraAtRunTime"] is None
    assert product["cameraProblem"] == "</OmniverseKit_Persp> does not exist on the composed stage"
    assert product["flags"]["camera"] == [product["cameraProblem"], "CA003"]
    assert "CA003" in product["findings"]


def test_a_prim_defined_at_the_runtime_cameras_path_is_still_judged(tmp_path: Path) -> None:
    path = tmp_path / "kit_xform.usda"
    path.write_text(KIT_XFORM)
    assert "CA004" in check_codes(path)
    product = product_json(path)
    assert product["profile"] == "omniverse"
    assert product["cameraAtRunTime"] is None
    assert "CA004" in product["flags"]["camera"]


def test_the_kit_corpus_file_agrees_with_check(shared_dir: Path) -> None:
    (path,) = shared_dir.glob("corpus/files/**/boxes_falling_on_groundplane.usda")
    assert check_codes(path) == ["ST003"]
    result = invoke("spec", "--format", "json", str(path))
    assert result.exit_code == 0, result.output
    (settings,) = json.loads(result.stdout)["files"][0]["settings"]
    assert settings["profile"] == "omniverse"
    for product in settings["products"]:
        assert product["camera"] == "/OmniverseKit_Persp"
        assert product["cameraProblem"] is None and "camera" not in product["flags"]
        assert product["cameraAtRunTime"]["profile"] == "omniverse"
        assert product["findings"] == []
    generic = invoke("spec", "--format", "json", "--profile", "generic", str(path))
    (settings,) = json.loads(generic.stdout)["files"][0]["settings"]
    assert all("CA003" in p["flags"]["camera"] for p in settings["products"])
