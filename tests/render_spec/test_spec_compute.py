"""What ``spec`` reads from stages, against hand-computed values: product
overrides (authored values only), forwarding, crop, overscan, non-square
pixels, time-sampled apertures and productName, a settings with no
products, a missing camera, the vars, and the same partial composition as check."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from bench_support import load_script
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.engine import partial as fastpath

REPO = Path(__file__).resolve().parents[2]

CAMERA = """
def Camera "cam"
{
    float horizontalAperture = 36
    float verticalAperture = 24
}
"""


def spec(path: Path, *args: str) -> dict:
    result = CliRunner().invoke(
        cli,
        [
            "spec",
            "--isolated",
            "--jobs",
            "1",
            "--timeout",
            "0",
            "--format",
            "json",
            *args,
            str(path),
        ],
    )
    assert result.exit_code == 0, result.output
    (file,) = json.loads(result.stdout)["files"]
    assert file["status"] == "computed"
    return file


def layer(tmp_path: Path, body: str, metadata: str = "", name: str = "shot.usda") -> Path:
    path = tmp_path / name
    path.write_text(f"#usda 1.0\n(\n{metadata}\n)\n{body}\n")
    return path


def only_product(file: dict) -> dict:
    (settings,) = file["settings"]
    (product,) = settings["products"]
    return product


def test_product_overrides_only_what_it_authors(tmp_path: Path) -> None:
    path = layer(
        tmp_path,
        CAMERA
        + """
def RenderSettings "settings"
{
    rel camera = </cam>
    rel products = [</beauty>, </half>]
    uniform int2 resolution = (1920, 1080)
    uniform float4 dataWindowNDC = (0, 0, 0.5, 1)
}
def RenderProduct "beauty"
{
    token productName = "beauty.exr"
}
def RenderProduct "half"
{
    token productName = "half.exr"
    uniform int2 resolution = (960, 540)
    uniform token aspectRatioConformPolicy = "cropAperture"
    uniform float4 dataWindowNDC = None
}
""",
    )
    (settings,) = spec(path)["settings"]
    beauty, half = settings["products"]
    # beauty authors nothing: the settings' values, authored or fallback.
    assert beauty["resolution"] == [1920, 1080]
    assert beauty["aspectRatioConformPolicy"] == "expandAperture"
    assert beauty["sources"]["resolution"]["from"] == "settings"
    assert beauty["sources"]["aspectRatioConformPolicy"]["from"] == "fallback"
    assert beauty["dataWindow"]["x"] == [0, 959]
    # half's own values win; its blocked dataWindowNDC is no opinion.
    assert half["resolution"] == [960, 540]
    line = path.read_text().splitlines().index("    uniform int2 resolution = (960, 540)") + 1
    source = half["sources"]["resolution"]
    assert (source["from"], source["path"], source["line"]) == ("product", "/half.resolution", line)
    assert Path(source["layer"]).resolve() == path.resolve()
    assert half["aspectRatioConformPolicy"] == "cropAperture"
    assert half["dataWindowNDC"] == [0.0, 0.0, 0.5, 1.0]
    assert half["sources"]["dataWindowNDC"]["from"] == "settings"
    assert half["dataWindow"]["x"] == [0, 479]
    # 36x24 (1.5) cropped to 16:9: the height shrinks to 36 * 9 / 16 = 20.25.
    assert half["aperture"]["conformed"] == [36.0, 20.25]
    assert beauty["aperture"]["conformed"] == [42.666668, 24.0]  # expanded: 24 * 16 / 9


def test_settings_fallbacks_reach_products(tmp_path: Path) -> None:
    path = layer(
        tmp_path,
        CAMERA
        + """
def RenderSettings "settings"
{
    rel camera = </cam>
    rel products = </p>
}
def RenderProduct "p"
{
}
""",
    )
    product = only_product(spec(path))
    assert product["resolution"] == [2048, 1080]  # the schema fallback
    assert product["pixelAspectRatio"] == 1.0
    assert product["dataWindowNDC"] == [0.0, 0.0, 1.0, 1.0]
    assert product["name"] == "" and product["type"] == "raster"
    # 36x24 expanded to 2048/1080: the width grows to 24 * 2048 / 1080.
    assert product["aperture"]["conformed"][0] == pytest.approx(24 * 2048 / 1080, rel=1e-6)
    assert product["aperture"]["adjusted"] == "width"


def test_relationships_are_forwarded(tmp_path: Path) -> None:
    path = layer(
        tmp_path,
        CAMERA
        + """
def Scope "wiring"
{
    rel shotCamera = </cam>
    rel outputs = [</beauty>]
}
def RenderSettings "settings"
{
    rel camera = </wiring.shotCamera>
    rel products = </wiring.outputs>
    uniform int2 resolution = (1920, 1080)
}
def RenderProduct "beauty"
{
    token productName = "beauty.exr"
}
""",
    )
    product = only_product(spec(path))
    assert product["path"] == "/beauty"
    assert product["camera"] == "/cam"
    assert product["cameraProblem"] is None
    assert product["aperture"]["camera"] == [36.0, 24.0]


def test_product_camera_wins_over_the_settings_camera(tmp_path: Path) -> None:
    path = layer(
        tmp_path,
        CAMERA
        + """
def Camera "wide"
{
    float horizontalAperture = 40
    float verticalAperture = 20
}
def RenderSettings "settings"
{
    rel camera = </cam>
    rel products = </p>
    uniform int2 resolution = (1920, 1080)
}
def RenderProduct "p"
{
    rel camera = </wide>
}
""",
    )
    product = only_product(spec(path))
    assert product["camera"] == "/wide"
    assert product["sources"]["camera"]["from"] == "product"
    assert product["aperture"]["conformed"] == [40.0, 22.5]  # 40 * 9 / 16


def test_crop_and_overscan_pixels(tmp_path: Path) -> None:
    path = layer(
        tmp_path,
        CAMERA
        + """
def RenderSettings "settings"
{
    rel camera = </cam>
    rel products = [</crop>, </over>]
    uniform int2 resolution = (1920, 1080)
}
def RenderProduct "crop"
{
    uniform float4 dataWindowNDC = (0.25, 0, 0.75, 0.25)
}
def RenderProduct "over"
{
    uniform float4 dataWindowNDC = (-0.05, -0.05, 1.05, 1.05)
}
""",
    )
    crop, over = spec(path)["settings"][0]["products"]
    assert crop["dataWindow"] == {
        "x": [480, 1439],
        "y": [0, 269],
        "yFromTop": [810, 1079],
        "width": 960,
        "height": 270,
    }
    assert over["dataWindow"]["x"] == [-96, 2015]
    assert over["dataWindow"]["y"] == [-54, 1133]
    assert (over["dataWindow"]["width"], over["dataWindow"]["height"]) == (2112, 1188)


def test_non_square_pixels(tmp_path: Path) -> None:
    path = layer(
        tmp_path,
        CAMERA
        + """
def RenderSettings "settings"
{
    rel camera = </cam>
    rel products = [</anamorphic>, </fit>]
    uniform int2 resolution = (960, 1080)
    uniform float pixelAspectRatio = 2
}
def RenderProduct "anamorphic"
{
}
def RenderProduct "fit"
{
    uniform token aspectRatioConformPolicy = "adjustPixelAspectRatio"
}
""",
    )
    anamorphic, fit = spec(path)["settings"][0]["products"]
    # 960x1080 with 2:1 pixels is 16:9: the 36x24 aperture widens to 24 * 16 / 9.
    assert anamorphic["aperture"]["conformed"] == [42.666668, 24.0]
    assert anamorphic["pixelAspectRatio"] == 2.0
    assert anamorphic["dataWindow"]["width"] == 960  # pixels, not image units
    # The pixels take the aperture's aspect over the resolution's: 1.5 / (960 / 1080).
    assert fit["pixelAspectRatio"] == 1.6875
    assert fit["aperture"]["conformed"] == [36.0, 24.0]
    assert fit["aperture"]["adjusted"] == "pixelAspectRatio"


SAMPLED = """
def Camera "cam"
{
    float horizontalAperture.timeSamples = {
        101: 36,
        102: 40,
    }
    float verticalAperture = 20.25
}
def RenderSettings "settings"
{
    rel camera = </cam>
    rel products = </p>
    uniform int2 resolution = (1920, 1080)
}
def RenderProduct "p"
{
    token productName.timeSamples = {
        101: "p.0101.exr",
        102: "p.0102.exr",
    }
}
"""


def test_time_sampled_aperture_and_product_name_at_the_start(tmp_path: Path) -> None:
    file = spec(layer(tmp_path, SAMPLED, "startTimeCode = 101\nendTimeCode = 102"))
    assert (file["time"], file["timeFrom"]) == (101.0, "startTimeCode")
    product = only_product(file)
    assert product["time"] == 101.0
    assert product["renderedTimes"] == [101.0, 102.0]
    assert product["aperture"]["camera"] == [36.0, 20.25]
    assert product["name"] == "p.0101.exr"
    # UsdRenderComputeSpec reads at Default: the aperture falls back to 20.955,
    # productName to "" (only samples are authored).
    differs = product["usdRenderComputeSpec"]["differs"]
    assert differs["aperture.camera"] == [20.955, 20.25]
    assert differs["name"] == ""
    assert product["usdRenderComputeSpec"]["included"] is True


def test_time_sampled_values_at_a_given_time(tmp_path: Path) -> None:
    file = spec(layer(tmp_path, SAMPLED, "startTimeCode = 101\nendTimeCode = 102"), "--time", "102")
    assert file["timeFrom"] == "--time"
    product = only_product(file)
    assert product["aperture"]["camera"] == [40.0, 20.25]
    assert product["aperture"]["conformed"] == [40.0, 22.5]  # wider than 16:9: expand height
    assert product["name"] == "p.0102.exr"


def test_samples_only_without_a_range_read_the_first_rendered_time(tmp_path: Path) -> None:
    # R2-1's case: apertures only as samples (a Houdini export), no time range.
    body = SAMPLED.replace("101:", "175:").replace("102:", "176:")
    file = spec(layer(tmp_path, body))
    assert (file["time"], file["timeFrom"]) == ("default", "default")
    product = only_product(file)
    assert product["time"] == 175.0
    assert product["renderedTimes"] == [175.0, 176.0]
    assert product["aperture"]["camera"] == [36.0, 20.25]
    assert product["name"] == "p.0101.exr"
    # What --help states as the default (it said Default, which the camera is not read at).
    help_text = " ".join(CliRunner().invoke(cli, ["spec", "--help"]).stdout.split())
    assert "else each camera's first rendered time]" in help_text


def test_a_sampled_product_name_under_a_still_camera_is_its_first_sample(tmp_path: Path) -> None:
    # No startTimeCode and no animated camera input: the product's time is
    # Default, at which productName has no value; its first sample is read, and
    # the reference page says so.
    body = SAMPLED.replace(
        """    float horizontalAperture.timeSamples = {
        101: 36,
        102: 40,
    }""",
        "    float horizontalAperture = 36",
    )
    product = only_product(spec(layer(tmp_path, body)))
    assert (product["time"], product["renderedTimes"]) == ("default", ["default"])
    assert product["name"] == "p.0101.exr"
    assert product["usdRenderComputeSpec"]["differs"] == {"name": ""}
    page = (REPO / "docs" / "reference" / "spec-json.md").read_text(encoding="utf-8")
    (row,) = [line for line in page.splitlines() if line.startswith("| `products[].name` |")]
    assert "has time samples, at its first sample" in row


def test_time_default_reads_default_values(tmp_path: Path) -> None:
    body = SAMPLED.replace("float verticalAperture = 20.25", "float verticalAperture = 20.25\n")
    body = body.replace(
        "float horizontalAperture.timeSamples",
        "float horizontalAperture = 30\n    float horizontalAperture.timeSamples",
    )
    file = spec(
        layer(tmp_path, body, "startTimeCode = 101\nendTimeCode = 102"), "--time", "default"
    )
    assert (file["time"], file["timeFrom"]) == ("default", "--time")
    product = only_product(file)
    assert product["time"] == "default"
    assert product["aperture"]["camera"] == [30.0, 20.25]
    assert product["usdRenderComputeSpec"]["differs"] == {}


def test_a_nan_read_at_both_times_is_no_difference(tmp_path: Path) -> None:
    # A NaN pixel aspect ratio gives a NaN conformed aperture at every time:
    # UsdRenderComputeSpec gives the same values, so nothing differs.
    body = """
def RenderSettings "settings"
{
    rel camera = </cam>
    rel products = </p>
    uniform int2 resolution = (100, 100)
    uniform float pixelAspectRatio = nan
}
def RenderProduct "p"
{
}
"""
    product = only_product(spec(layer(tmp_path, CAMERA + body)))
    assert product["aperture"]["conformed"] == [None, 24.0]
    assert product["usdRenderComputeSpec"]["differs"] == {}


def test_a_settings_with_no_products(tmp_path: Path) -> None:
    path = layer(
        tmp_path,
        CAMERA
        + """
def RenderSettings "settings"
{
    rel camera = </cam>
    uniform int2 resolution = (1920, 1080)
}
""",
    )
    (settings,) = spec(path)["settings"]
    assert settings["products"] == []
    assert "SE015" in settings["findings"]
    base = settings["base"]
    assert base["path"] is None and base["vars"] == []
    assert base["aperture"]["conformed"] == [42.666668, 24.0]
    assert base["usdRenderComputeSpec"]["included"] is False


def test_a_missing_camera(tmp_path: Path) -> None:
    path = layer(
        tmp_path,
        """
def RenderSettings "settings"
{
    rel camera = </nowhere>
    rel products = </p>
    uniform int2 resolution = (1920, 1080)
}
def RenderProduct "p"
{
    token productName = "p.exr"
}
""",
    )
    product = only_product(spec(path))
    assert product["camera"] == "/nowhere"
    assert product["cameraProblem"] == "</nowhere> does not exist on the composed stage"
    assert product["aperture"] is None and product["screenWindow"] is None
    assert product["shutter"] is None
    assert product["flags"]["camera"] == [
        "</nowhere> does not exist on the composed stage",
        "CA003",
    ]
    assert "CA003" in product["findings"]
    assert product["usdRenderComputeSpec"] == {
        "included": False,
        "reason": "drops the product: could not find camera </nowhere>",
        "differs": {},
    }
    # What does not need the camera is still there.
    assert product["dataWindow"]["width"] == 1920


def test_an_empty_data_window_is_flagged(tmp_path: Path) -> None:
    path = layer(
        tmp_path,
        CAMERA
        + """
def RenderSettings "settings"
{
    rel camera = </cam>
    rel products = </p>
    uniform int2 resolution = (1920, 1080)
}
def RenderProduct "p"
{
    uniform float4 dataWindowNDC = (0.75, 0.25, 0.25, 0.75)
}
""",
    )
    product = only_product(spec(path))
    assert product["dataWindow"]["width"] == 0
    assert product["flags"]["dataWindow"] == ["the data window contains no pixel centre"]
    assert product["flags"]["dataWindowNDC"] == ["SE003"]


def test_vars_in_order_with_namespaced_settings(tmp_path: Path) -> None:
    path = layer(
        tmp_path,
        CAMERA
        + """
def RenderSettings "settings"
{
    rel camera = </cam>
    rel products = </p>
    uniform int arnold:AA_samples = 4
}
def RenderProduct "p"
{
    rel orderedVars = [</vars/beauty>, </cam>, </vars/depth>]
    string driver:parameters:artist = "lee"
}
def Scope "vars"
{
    def RenderVar "beauty"
    {
        uniform string sourceName = "Ci"
        uniform string driver:parameters:aov:name = "rgba"
        uniform float2 arnold:filter:width = (2, 2)
    }
    def RenderVar "depth"
    {
        uniform token dataType = "float"
        uniform string sourceName = "z"
    }
}
""",
    )
    file = spec(path)
    (settings,) = file["settings"]
    assert settings["namespacedSettings"] == {"arnold:AA_samples": 4}
    product = settings["products"][0]
    assert product["namespacedSettings"] == {"driver:parameters:artist": "lee"}
    # The Camera target is no RenderVar: skipped (spec.cpp: "Skipping").
    assert [v["path"] for v in product["vars"]] == ["/vars/beauty", "/vars/depth"]
    beauty, depth = product["vars"]
    assert beauty == {
        "path": "/vars/beauty",
        "name": "beauty",
        "dataType": "color3f",
        "sourceName": "Ci",
        "sourceType": "raw",
        "namespacedSettings": {
            "arnold:filter:width": [2.0, 2.0],
            "driver:parameters:aov:name": "rgba",
        },
    }
    assert (depth["dataType"], depth["sourceName"]) == ("float", "z")


def test_motion_blur_disabled_renders_an_instant(tmp_path: Path) -> None:
    path = layer(
        tmp_path,
        """
def Camera "cam"
{
    double shutter:open = -0.25
    double shutter:close = 0.25
}
def RenderSettings "settings"
{
    rel camera = </cam>
    rel products = [</blurred>, </sharp>]
}
def RenderProduct "blurred"
{
}
def RenderProduct "sharp"
{
    uniform bool disableMotionBlur = 1
}
""",
    )
    blurred, sharp = spec(path)["settings"][0]["products"]
    assert blurred["shutter"] == [-0.25, 0.25]
    assert sharp["shutter"] == [0.0, 0.0] and sharp["disableMotionBlur"] is True


def test_primary_settings_come_first_and_can_be_chosen(tmp_path: Path) -> None:
    body = (
        CAMERA
        + """
def RenderSettings "a"
{
    rel camera = </cam>
}
def RenderSettings "b"
{
    rel camera = </cam>
}
"""
    )
    path = layer(tmp_path, body, 'renderSettingsPrimPath = "/b"')
    file = spec(path)
    assert [(s["path"], s["primary"]) for s in file["settings"]] == [("/b", True), ("/a", False)]
    assert file["renderSettingsPrimPath"] == "/b"
    assert [s["path"] for s in spec(path, "--settings", "/a")["settings"]] == ["/a"]
    assert all(s["profile"] == "generic" for s in file["settings"])


def test_findings_are_attributed_to_the_products_they_concern(tmp_path: Path) -> None:
    path = layer(
        tmp_path,
        CAMERA
        + """
def Xform "rig"
{
}
def RenderSettings "settings"
{
    rel camera = </rig>
    rel products = [</own>, </inherits>]
}
def RenderProduct "own"
{
    rel camera = </cam>
    token productName = "own.exr"
    rel orderedVars = </v>
}
def RenderProduct "inherits"
{
    token productName = "inherits.exr"
}
def RenderVar "v"
{
    uniform string sourceName = ""
}
""",
    )
    own, inherits = spec(path)["settings"][0]["products"]
    # The settings' camera (CA004) is overridden by own's camera: not own's problem.
    assert "CA004" not in own["findings"] and "CA004" in inherits["findings"]
    assert "VA001" in own["findings"] and "VA001" not in inherits["findings"]
    assert "PR004" in inherits["findings"]


def test_spec_reads_the_partly_composed_stage_check_lints(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    shot = load_script("generate").generate_shot(tmp_path, prims=3000, fmt="usda")
    full = spec(shot)
    seen = []
    real = fastpath.open_partial

    def recording(path: str, wants_type):
        opened = real(path, wants_type)
        seen.append(opened.stage is not None)
        return opened

    monkeypatch.setattr(fastpath, "FLAT_STAGES_COMPOSE_FULLY", False)
    monkeypatch.setattr(fastpath, "open_partial", recording)
    partial = spec(shot)
    assert seen == [True]  # one open, partly composed, for the rules and the spec alike
    assert partial["settings"] == full["settings"]
    assert {(s["path"], len(s["products"])) for s in partial["settings"]} == {
        ("/Render/Settings", 2),
        ("/Render/RigSettings", 1),
        ("/Render/LostSettings", 1),
    }


def test_the_profile_each_settings_is_judged_under(tmp_path: Path) -> None:
    path = layer(
        tmp_path,
        CAMERA
        + """
def RenderSettings "karma"
{
    rel camera = </cam>
    uniform int karma:global:pixelsamples = 9
}
def RenderSettings "plain"
{
    rel camera = </cam>
}
""",
    )
    karma, plain = spec(path)["settings"]
    assert karma["profile"] == "karma" and "karma:" in karma["profileReason"]
    assert plain["profile"] == "generic"
    forced = spec(path, "--profile", "arnold")["settings"]
    assert {s["profile"] for s in forced} == {"arnold"}
