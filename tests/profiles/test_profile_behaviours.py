"""What a renderer does about a rule's condition, where the rule's own
wording (the schema's, UsdRenderComputeSpec's) says otherwise: a finding
judged under that renderer's profile says what the renderer does (R2-5)."""

from __future__ import annotations

from pathlib import Path

from usdrender_lint.engine import Linter
from usdrender_lint.profiles import PROFILES, Profiler
from usdrender_lint.profiles.effective import profile_treatment
from usdrender_lint.registry import build_registry
from usdrender_lint.testing import all_rules

NO_CAMERA = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel products = </Render/Beauty>
    }
    def RenderProduct "Beauty"
    {
        token productName = "beauty.$F4.exr"
        rel orderedVars = </Render/Color>
    }
    def RenderVar "Color"
    {
        string sourceName = "Ci"
    }
}
def Camera "Cam"
{
}
"""


def _lint(tmp_path: Path, text: str, profile: str):
    path = tmp_path / "shot.usda"
    path.write_text(text, encoding="utf-8")
    linter = Linter(all_rules(), raise_errors=True, profiler=Profiler(lambda f: (profile, "test")))
    result = linter.lint_path(str(path))
    assert result.status == "linted", result.error
    return result.findings


def _one(findings, code: str):
    (found,) = [f for f in findings if f.code == code]
    return found


def test_every_behaviour_cites_its_renderer() -> None:
    for profile in PROFILES.values():
        for behaviour in profile.behaviours:
            assert behaviour.what and behaviour.source, (profile.name, behaviour.code)


def test_ca001_under_karma_says_husk_picks_a_camera_rather_than_dropping_the_product(
    tmp_path: Path,
) -> None:
    # XUSD_RenderSettings::loadFromOptions: with no camera on the settings or
    # a product, husk takes one from the stage and warns; it drops nothing.
    karma = _one(_lint(tmp_path, NO_CAMERA, "karma"), "CA001")
    assert karma.severity.value == "error"
    assert "husk does not drop the product" in karma.message
    assert "No camera in render settings, defaulting to" in karma.message
    assert "UsdRenderComputeSpec drops" not in karma.message
    generic = _one(_lint(tmp_path, NO_CAMERA, "generic"), "CA001")
    assert 'UsdRenderComputeSpec drops the product ("Could not find camera")' in generic.message


def test_explain_says_what_the_renderer_does() -> None:
    ca001 = build_registry().by_code("CA001")
    (karma,) = [line for line in profile_treatment(ca001) if line.startswith("karma:")]
    assert "husk does not drop the product" in karma
    assert "XUSD_RenderSettings.C" in karma


SAMPLED = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        int karma:global:samplesperpixel = 9
        rel camera = </Cam>
        rel products = </Render/Beauty>
        uniform int2 resolution.timeSamples = {
            1001: (1920, 1080),
            1002: (1280, 720),
        }
    }
    def RenderProduct "Beauty"
    {
        token productName.timeSamples = {
            1001: "beauty.1001.exr",
        }
        rel orderedVars = </Render/Color>
    }
    def RenderVar "Color"
    {
        string sourceName = "Ci"
    }
}
def Camera "Cam"
{
}
"""


def test_se017_under_karma_is_info_as_husk_renders_the_samples(tmp_path: Path) -> None:
    # XUSD_RenderSettings::loadFromPrim and XUSD_RenderProduct::updateSettings
    # read the render prims at ctx.evalTime(), the frame husk renders.
    karma = [f for f in _lint(tmp_path, SAMPLED, "karma") if f.code == "SE017"]
    assert {f.location.path for f in karma} == {
        "/Render/Settings.resolution",
        "/Render/Beauty.productName",
    }
    for finding in karma:
        assert finding.severity.value == "info"
        assert "husk reads it at the frame it renders and follows the samples" in finding.message
        assert "as UsdRenderComputeSpec does" in finding.message
        assert "renderers read it once" not in finding.message
    generic = [f for f in _lint(tmp_path, SAMPLED, "generic") if f.code == "SE017"]
    assert {f.severity.value for f in generic} == {"warning"}
    assert any("renderers read it once at the default time" in f.message for f in generic)
    assert any("so consumers reading at the default time get ''" in f.message for f in generic)


NO_NAME = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        int arnold:global:AA_samples = 3
        rel camera = </Cam>
        rel products = </Render/Beauty>
    }
    def RenderProduct "Beauty"
    {
        rel orderedVars = </Render/Color>
    }
    def RenderVar "Color"
    {
        string sourceName = "RGBA"
    }
}
def Camera "Cam"
{
}
"""


def test_pr001_under_arnold_says_kick_names_the_file_after_the_prim(tmp_path: Path) -> None:
    # arnold-usd rendersettings_utils.cpp, DeduceDriverFromFilename: with an
    # empty productName the driver's filename is the product prim's name.
    arnold = _one(_lint(tmp_path, NO_NAME, "arnold"), "PR001")
    assert arnold.severity.value == "error"
    assert "writes the image under the product prim's name" in arnold.message
    assert "no name to write to" not in arnold.message
    generic = _one(_lint(tmp_path, NO_NAME, "generic"), "PR001")
    assert "the display driver has no name to write to" in generic.message


def test_se017_under_arnold_is_info_as_kick_renders_the_samples(tmp_path: Path) -> None:
    # arnold-usd's ReadRenderSettings reads at time.frame; its test_0159 renders
    # the frame-2 samples of resolution and productName with kick -frame 2.
    text = SAMPLED.replace("int karma:global:samplesperpixel", "int arnold:global:AA_samples")
    arnold = [f for f in _lint(tmp_path, text, "arnold") if f.code == "SE017"]
    assert len(arnold) == 2
    for finding in arnold:
        assert finding.severity.value == "info"
        assert "arnold-usd reads it at the frame it renders" in finding.message
