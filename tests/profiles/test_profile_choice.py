"""Renderer profiles (catalog R2-5): which profile a configuration is judged
under, what a profile changes, and how findings record it."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.config import ConfigError, Settings, read_config_file
from usdrender_lint.engine import Linter
from usdrender_lint.model import Severity
from usdrender_lint.profiles import GENERIC, PROFILES, ProfileChoice, Profiler
from usdrender_lint.profiles.model import judge
from usdrender_lint.running.pipeline import make_linter
from usdrender_lint.testing import all_rules

TWO_RENDERERS = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "KarmaShot"
    {
        int karma:global:samplesperpixel = 9
        rel products = </Render/KarmaBeauty>
    }
    def RenderProduct "KarmaBeauty"
    {
        token productName = "husk:null_raster"
    }
    def RenderSettings "ArnoldShot"
    {
        rel products = </Render/ArnoldBeauty>
    }
    def RenderProduct "ArnoldBeauty"
    {
        string arnold:driver = "driver_tif"
        token productName = "husk:null_raster"
    }
}
"""

KIT_STAGE = """#usda 1.0
def OmniLidar "Lidar"
{
}
def Scope "Render"
{
    def "OmniverseKit"
    {
        def "HydraTextures"
        {
            def RenderProduct "Viewport"
            {
                rel camera = </OmniverseKit_Persp>
                rel orderedVars = </Render/Vars/LdrColor>
            }
        }
    }
    def RenderSettings "OmniverseGlobalRenderSettings"
    {
        rel products = </Render/OmniverseKit/HydraTextures/Viewport>
    }
    def RenderSettings "LidarSettings"
    {
        token omni:rtx:rendermode = "RaytracedLighting"
        rel camera = </Lidar>
        rel products = </Render/LidarProduct>
    }
    def RenderProduct "LidarProduct"
    {
        rel orderedVars = </Render/Vars/LdrColor>
    }
    def Scope "Vars"
    {
        def RenderVar "LdrColor"
        {
            string sourceName = "LdrColor"
        }
    }
}
"""


def _lint(tmp_path: Path, text: str, profile: tuple[str, str] | None = None):
    path = tmp_path / "shot.usda"
    path.write_text(text, encoding="utf-8")
    linter = Linter(all_rules(), raise_errors=True, profiler=Profiler(_fixed(profile)))
    result = linter.lint_path(str(path))
    assert result.status == "linted", result.error
    return result.findings


def _fixed(profile):
    return (lambda file: profile) if profile else None


def _pairs(findings) -> set[tuple[str, str | None, str | None]]:
    return {(f.code, f.location.path, f.profile) for f in findings}


def test_auto_decides_per_render_settings(tmp_path: Path) -> None:
    found = _pairs(_lint(tmp_path, TWO_RENDERERS))
    # Each renderer's rules run on its own configuration only.
    assert ("KA001", "/Render/KarmaBeauty.productName", "karma") in found
    assert ("AR001", "/Render/ArnoldBeauty.arnold:driver", "arnold") in found
    assert not any(code == "KA001" and "Arnold" in (path or "") for code, path, _ in found)
    findings = _lint(tmp_path, TWO_RENDERERS)
    reason = next(f.profile_reason for f in findings if f.code == "KA001")
    assert reason.startswith("auto: the property </Render/KarmaShot.karma:global:samplesperpixel>")


def test_several_renderers_evidence_is_generic(tmp_path: Path) -> None:
    text = TWO_RENDERERS.replace(
        "int karma:global:samplesperpixel = 9",
        "int karma:global:samplesperpixel = 9\n        int arnold:global:AA_samples = 3",
    )
    findings = _lint(tmp_path, text)
    karma_shot = [f for f in findings if (f.location.path or "").startswith("/Render/Karma")]
    assert not any(f.code == "KA001" for f in karma_shot)
    assert karma_shot and {f.profile for f in karma_shot} == {"generic"}
    assert "several renderers (karma: 1, arnold: 1)" in karma_shot[0].profile_reason


def test_explicit_profile_wins_and_says_where(tmp_path: Path) -> None:
    findings = _lint(tmp_path, TWO_RENDERERS, ("karma", "--profile karma"))
    assert {f.profile for f in findings} == {"karma"}
    assert {f.profile_reason for f in findings} == {"--profile karma"}
    # Under karma the arnold rule does not run, KA001 now also judges the Arnold shot.
    codes = {(f.code, f.location.path) for f in findings}
    assert ("KA001", "/Render/ArnoldBeauty.productName") in codes
    assert not any(code == "AR001" for code, _ in codes)


def test_omniverse_profile_drops_what_rtx_does_not_read(tmp_path: Path) -> None:
    auto = _lint(tmp_path, KIT_STAGE)
    codes = {(f.code, f.location.path) for f in auto}
    # PR001: RTX products are buffers addressed by path; CA003: Kit's session
    # camera; CA004: an OmniLidar is the product's sensor.
    assert not any(code in ("PR001", "CA003", "CA004") for code, _ in codes)
    assert {f.profile for f in auto} == {"omniverse"}
    generic = _lint(tmp_path, KIT_STAGE, ("generic", "test"))
    gcodes = {(f.code, f.location.path) for f in generic}
    assert ("PR001", "/Render/OmniverseKit/HydraTextures/Viewport") in gcodes
    assert ("CA003", "/Render/OmniverseKit/HydraTextures/Viewport.camera") in gcodes
    assert ("CA004", "/Render/LidarSettings.camera") in gcodes


INVERTED_SHUTTER = """#usda 1.0
def Camera "Cam"
{
    double shutter:close = -0.25
    double shutter:open = 0.25
}
def Scope "Render"
{
    def RenderSettings "Viewport"
    {
        token omni:rtx:rendermode = "RaytracedLighting"
        rel camera = </Cam>
    }
}
"""


def test_omniverse_profile_drops_ca008_as_rtx_ignores_the_shutter(tmp_path: Path) -> None:
    # RTX does not read shutter:open / shutter:close (the profile's CA008 change).
    auto = _lint(tmp_path, INVERTED_SHUTTER)
    assert {f.profile for f in auto} == {"omniverse"}
    assert not any(f.code == "CA008" for f in auto)
    generic = _lint(tmp_path, INVERTED_SHUTTER, ("generic", "test"))
    assert ("CA008", "/Cam") in {(f.code, f.location.path) for f in generic}
    # A renderer that reads the shutter keeps the finding.
    karma = _lint(tmp_path, INVERTED_SHUTTER, ("karma", "test"))
    assert ("CA008", "/Cam") in {(f.code, f.location.path) for f in karma}


ACOUSTIC_STAGE = """#usda 1.0
def OmniAcoustic "Acoustic" (
    prepend apiSchemas = ["OmniSensorGenericAcousticWpmAPI"]
)
{
}
def Scope "Render"
{
    def RenderProduct "AcousticProduct"
    {
        rel camera = </Acoustic>
        rel orderedVars = </Render/Output>
    }
    def RenderVar "Output"
    {
        string sourceName = "GenericModelOutput"
    }
}
"""


def test_an_rtx_acoustic_sensor_is_a_camera_under_omniverse(tmp_path: Path) -> None:
    # Isaac Sim docs, RTX Acoustic Sensor: a render product is attached to the
    # OmniAcoustic prim, as to an OmniLidar or OmniRadar.
    auto = _lint(tmp_path, ACOUSTIC_STAGE)
    assert {f.profile for f in auto} == {"omniverse"}
    assert not any(f.code in ("CA004", "ST010") for f in auto)
    generic = _lint(tmp_path, ACOUSTIC_STAGE, ("generic", "test"))
    assert ("CA004", "/Render/AcousticProduct.camera") in {
        (f.code, f.location.path) for f in generic
    }


ARNOLD_NO_BLUR = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        int arnold:global:AA_samples = 3
        uniform bool instantaneousShutter = 1
    }
}
"""


def test_arnold_keeps_instantaneous_shutter_which_arnold_usd_reads(tmp_path: Path) -> None:
    # arnold-usd's USD procedural disables motion blur from instantaneousShutter
    # and reads no disableMotionBlur: SE007's advice (and fix) would undo it.
    auto = _lint(tmp_path, ARNOLD_NO_BLUR)
    assert {f.profile for f in auto} == {"arnold"}
    assert not any(f.code == "SE007" for f in auto)
    generic = _lint(tmp_path, ARNOLD_NO_BLUR, ("generic", "test"))
    assert ("SE007", "/Render/Settings.instantaneousShutter") in {
        (f.code, f.location.path) for f in generic
    }


def test_kit_scope_is_evidence(tmp_path: Path) -> None:
    findings = _lint(tmp_path, KIT_STAGE)
    reasons = {f.profile_reason for f in findings}
    assert any("in /Render/OmniverseKit" in r for r in reasons)


def test_ca004_names_the_types_the_profile_accepts(tmp_path: Path) -> None:
    text = KIT_STAGE.replace('def OmniLidar "Lidar"', 'def Xform "Lidar"')
    findings = _lint(tmp_path, text)
    (ca004,) = [f for f in findings if f.code == "CA004"]
    assert "nor OmniLidar, OmniRadar, OmniAcoustic, which this profile accepts" in ca004.message


def test_a_prim_shared_with_a_generic_configuration_keeps_its_finding(tmp_path: Path) -> None:
    shared = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Rtx"
    {
        token omni:rtx:rendermode = "RaytracedLighting"
        rel products = </Render/Shared>
    }
    def RenderSettings "Plain"
    {
        rel products = </Render/Shared>
    }
    def RenderProduct "Shared"
    {
    }
}
"""
    findings = _lint(tmp_path, shared)
    (pr001,) = [f for f in findings if f.code == "PR001"]
    assert pr001.profile == "generic"


def test_judge_takes_the_strictest_verdict() -> None:
    omniverse = ProfileChoice(PROFILES["omniverse"], "x")
    generic = ProfileChoice(GENERIC, "y")
    assert judge("PR001", Severity.ERROR, None, (omniverse,)) is None
    assert judge("PR001", Severity.ERROR, None, (omniverse, generic)) == (generic, Severity.ERROR)
    assert judge("KA001", Severity.WARNING, "karma", (generic,)) is None


def test_every_profile_change_and_acceptance_cites_a_source() -> None:
    for profile in PROFILES.values():
        for change in profile.changes:
            assert change.source and change.why, (profile.name, change.code)
        fields = ("camera_types", "runtime_cameras", "prim_types", "product_types")
        for field in (*fields, "layer_data", "var_outputs"):
            for accepted in getattr(profile, field):
                assert accepted.source and accepted.why, (profile.name, accepted.name)


def test_profiles_with_evidence_of_their_own_cite_it() -> None:
    # Namespaces, API schemas and scopes carry no source of their own: the
    # profile's evidence_sources must show they are the renderer's.
    for name, profile in PROFILES.items():
        if profile.namespaces or profile.api_schemas or profile.scopes:
            assert profile.evidence_sources, name


def test_every_renderer_scope_is_named_by_a_cited_source() -> None:
    # A scope is a prim path a renderer's application writes: some source the
    # profile cites must show that path.
    for name, profile in PROFILES.items():
        for scope in profile.scopes:
            assert any(scope.rstrip("/") in s for s in profile.evidence_sources), (name, scope)


SENSOR_STAGE = """#usda 1.0
def OmniLidar "Lidar"
{
}
def Scope "Render"
{
    def RenderProduct "LidarProduct"
    {
        rel camera = </Lidar>
        rel orderedVars = </Render/Vars/Points>
    }
    def Scope "Vars"
    {
        def RenderVar "Points"
        {
            string sourceName = "GenericModelOutput"
        }
    }
}
"""


def test_a_camera_target_of_a_renderers_own_type_is_evidence(tmp_path: Path) -> None:
    # An ovrtx sensor stage: no RenderSettings, no omni:rtx: property.
    auto = _lint(tmp_path, SENSOR_STAGE)
    assert {f.profile for f in auto} == {"omniverse"}
    reason = auto[0].profile_reason
    assert reason.startswith(
        "auto: the camera target </Lidar> of </Render/LidarProduct>, an OmniLidar"
    )
    assert not {"CA004", "PR001"} & {f.code for f in auto}
    generic = {f.code for f in _lint(tmp_path, SENSOR_STAGE, ("generic", "test"))}
    assert {"CA004", "PR001"} <= generic


def test_kit_session_camera_targets_and_layer_data_are_evidence(tmp_path: Path) -> None:
    product = """
def Scope "Render"
{
    def RenderProduct "Capture"
    {
        rel camera = </OmniverseKit_Persp>
        rel orderedVars = </Render/LdrColor>
    }
    def RenderVar "LdrColor"
    {
        string sourceName = "LdrColor"
    }
}
"""
    found = _lint(tmp_path, "#usda 1.0\n" + product)
    assert {f.profile for f in found} == {"omniverse"}
    assert "</OmniverseKit_Persp> of </Render/Capture>, a camera the renderer's application" in (
        found[0].profile_reason
    )
    assert "CA003" not in {f.code for f in found}
    saved = """#usda 1.0
(
    customLayerData = {
        dictionary cameraSettings = {
            string boundCamera = "/OmniverseKit_Persp"
        }
    }
)
def Camera "Cam"
{
}
def Scope "Render"
{
    def RenderProduct "Capture"
    {
        rel camera = </Cam>
        rel orderedVars = </Render/LdrColor>
    }
    def RenderVar "LdrColor"
    {
        string sourceName = "LdrColor"
    }
}
"""
    found = _lint(tmp_path, saved)
    assert {f.profile for f in found} == {"omniverse"}
    assert found[0].profile_reason == (
        "auto: the root layer's customLayerData cameraSettings:boundCamera"
    )
    plain = _lint(tmp_path, saved.replace("boundCamera", "favouriteCamera"))
    assert {f.profile for f in plain} == {"generic"}


def test_omni_kit_properties_are_no_evidence_of_rtx(tmp_path: Path) -> None:
    # Kit's render-prim settings are omni:rtx:* (omni.usd.schema.render_settings.rtx);
    # omni:kit:* (centerOfInterest, cameraLock) are Kit's camera properties.
    text = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        custom bool omni:kit:cameraLock = 1
        rel products = </Render/Beauty>
    }
    def RenderProduct "Beauty"
    {
        token productName = ""
    }
}
"""
    found = _lint(tmp_path, text)
    assert {f.profile for f in found} == {"generic"}
    assert "PR001" in {f.code for f in found}
    rtx = _lint(tmp_path, text.replace("omni:kit:cameraLock", "omni:rtx:rt:demoire"))
    assert {f.profile for f in rtx} == {"omniverse"}


def test_moonray_and_cycles_namespaces_are_evidence(tmp_path: Path) -> None:
    settings = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        SETTING
        rel products = </Render/Beauty>
    }
    def RenderProduct "Beauty"
    {
        token productName = "beauty.exr"
    }
}
"""
    moonray = _lint(
        tmp_path, settings.replace("SETTING", "int moonray:sceneVariable:max_depth = 2")
    )
    assert {f.profile for f in moonray} == {"moonray"}
    assert moonray[0].profile_reason.startswith(
        "auto: the property </Render/Settings.moonray:sceneVariable:max_depth>"
    )
    cycles = _lint(tmp_path, settings.replace("SETTING", "int cycles:samples = 64"))
    assert {f.profile for f in cycles} == {"cycles"}
    # Cycles' and Karma's settings on one prim: several renderers, the schema alone.
    both = _lint(
        tmp_path,
        settings.replace("SETTING", "int cycles:samples = 64\n        int karma:global:x = 1"),
    )
    assert {f.profile for f in both} == {"generic"}
    assert "several renderers (karma: 1, cycles: 1)" in both[0].profile_reason


def test_renderer_rules_cite_their_renderer_and_belong_to_its_family() -> None:
    for rule in (type(r) for r in all_rules()):
        if rule.profile is None:
            continue
        profile = PROFILES[rule.profile]
        assert rule.code.startswith(profile.family), rule.code
        why = rule.__doc__.split("## Why is this bad?")[1]
        sources = ("docs", ".cpp", "arnold-usd", "HoudiniUsdBridge")
        assert any(s in why for s in sources), rule.code


def test_ka002_quotes_the_karma_render_settings_page_as_it_reads() -> None:
    # The Karma Render Settings LOP page, Output Picture, word for word.
    from usdrender_lint.rules.karma.ka002_frame_token_missing import FrameTokenMissing

    doc = " ".join((FrameTokenMissing.__doc__ or "").split())
    assert (
        '"Include $F in the file name to insert the frame number. This is necessary when '
        'rendering animation."' in doc
    )


def test_config_profile_keys(tmp_path: Path) -> None:
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text(
        'profile = "arnold"\n[per-path-profiles]\n"kit/**" = "omniverse"\n', encoding="utf-8"
    )
    settings = read_config_file(config)
    assert settings.profile == "arnold"
    choose = make_linter(settings).profiler.choose
    kit = tmp_path / "kit" / "a.usda"
    assert choose(str(kit)) == (
        "omniverse",
        f"{config}: per-path-profiles.kit/** = omniverse",
    )
    assert choose(str(tmp_path / "b.usda")) == ("arnold", f"{config}: profile = arnold")
    flagged = make_linter(settings.merged(profile="generic")).profiler.choose
    assert flagged(str(kit)) == ("generic", "--profile generic")
    config.write_text('profile = "vray"\n', encoding="utf-8")
    with pytest.raises(
        ConfigError, match="profile: unknown profile 'vray' \\(known: auto, generic"
    ):
        make_linter(read_config_file(config))


def test_settings_default_is_auto() -> None:
    assert Settings().profile == "auto"


def test_cli_profile_flag_and_json_fields(tmp_path: Path) -> None:
    path = tmp_path / "shot.usda"
    path.write_text(KIT_STAGE, encoding="utf-8")
    runner = CliRunner()
    auto = json.loads(
        runner.invoke(cli, ["check", "--isolated", "--format", "json", str(path)]).output
    )
    pinned = runner.invoke(
        cli, ["check", "--isolated", "--format", "json", "--profile", "generic", str(path)]
    )
    generic = json.loads(pinned.output)
    auto_codes = {f["code"] for f in auto["files"][0]["findings"]}
    generic_codes = {f["code"] for f in generic["files"][0]["findings"]}
    assert "PR001" in generic_codes - auto_codes
    assert {f["profile"] for f in generic["files"][0]["findings"]} == {"generic"}
    assert {f["profile_reason"] for f in generic["files"][0]["findings"]} == {"--profile generic"}
    sarif = json.loads(
        runner.invoke(cli, ["check", "--isolated", "--format", "sarif", str(path)]).output
    )
    props = sarif["runs"][0]["results"][0]["properties"]
    assert props["profile"] == "omniverse" and props["profileReason"].startswith("auto:")
    text = runner.invoke(cli, ["check", "--isolated", "--show-info", str(path)]).output
    assert "[profile omniverse: auto:" in text
    plain = runner.invoke(cli, ["check", "--isolated", str(path)]).output
    assert "[profile " not in plain


def test_rules_and_explain_show_profiles() -> None:
    runner = CliRunner()
    rows = json.loads(
        runner.invoke(cli, ["rules", "--profile", "omniverse", "--format", "json"]).output
    )
    by_code = {row["code"]: row for row in rows}
    assert by_code["PR001"]["enabled"] is False and by_code["PR001"]["effective_severity"] is None
    assert "ovrtx" in by_code["PR001"]["why"]
    assert by_code["OV001"]["enabled"] is True
    assert by_code["KA001"]["enabled"] is False
    assert by_code["SE003"] == {**by_code["SE003"], "enabled": True, "effective_severity": "error"}
    plain = json.loads(runner.invoke(cli, ["rules", "--format", "json"]).output)
    assert "enabled" not in plain[0]
    text = runner.invoke(cli, ["explain", "PR001"]).output
    assert "## Under each profile" in text
    assert "- omniverse: off (an RTX render product" in text
    assert "- karma: error, as by default" in text
    bad = runner.invoke(cli, ["check", "--profile", "vray", "x.usda"])
    assert bad.exit_code == 2


def test_camera_and_layer_evidence_through_composition(tmp_path: Path) -> None:
    # The lidar comes through a payload, the product's camera from a sublayer;
    # a sublayer's customLayerData is not the root layer's (Kit writes the root's).
    (tmp_path / "sensor.usda").write_text(
        '#usda 1.0\ndef OmniLidar "Sensor"\n{\n}\n', encoding="utf-8"
    )
    (tmp_path / "render.usda").write_text(
        """#usda 1.0
(
    customLayerData = {
        dictionary cameraSettings = {
            string boundCamera = "/OmniverseKit_Persp"
        }
    }
)
def Scope "Render"
{
    def RenderProduct "Lidar"
    {
        rel camera = </Rig/Lidar>
    }
}
""",
        encoding="utf-8",
    )
    root = """#usda 1.0
(
    subLayers = [@render.usda@]
)
def Xform "Rig"
{
    def "Lidar" (
        prepend payload = @sensor.usda@</Sensor>
    )
    {
    }
}
"""
    found = _lint(tmp_path, root)
    assert {f.profile for f in found} == {"omniverse"}
    assert found[0].profile_reason == (
        "auto: the camera target </Rig/Lidar> of </Render/Lidar>, an OmniLidar"
    )
    unloaded = _lint(tmp_path, root.replace("prepend payload = @sensor.usda@</Sensor>", ""))
    assert {f.profile for f in unloaded} == {"generic"}


ARNOLD_IMAGER_STAGE = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Shot"
    {
        int arnold:global:AA_samples = 4
        string arnold:global:imager = "/Render/Imagers/Denoise"
        rel products = </Render/Beauty>
    }
    def RenderProduct "Beauty"
    {
        token productName = "beauty.exr"
    }
    def Scope "Imagers"
    {
        def ArnoldNodeGraph "Denoise"
        {
        }
    }
}
"""


def test_arnold_accepts_its_own_prim_types(tmp_path: Path) -> None:
    # arnold-usd registers ArnoldNodeGraph (imagers, AOV shaders under /Render)
    # and its other Arnold* types; they are unknown only where it is not installed.
    auto = _lint(tmp_path, ARNOLD_IMAGER_STAGE)
    assert {f.profile for f in auto} == {"arnold"}
    assert "ST010" not in {f.code for f in auto}
    generic = _lint(tmp_path, ARNOLD_IMAGER_STAGE, ("generic", "test"))
    assert ("ST010", "/Render/Imagers/Denoise", "generic") in _pairs(generic)


def test_explain_says_which_names_a_profile_accepts_for_a_rule() -> None:
    # A profile that accepts its renderer's names leaves the rule's severity
    # alone but reports fewer things; explain (and the rule's page) says so.
    runner = CliRunner()
    st010 = runner.invoke(cli, ["explain", "ST010"]).output
    assert "- renderman: warning, as by default; accepts `Pxr*`" in st010
    assert "- omniverse: warning, as by default; accepts `OmniSensor`, `OmniLidar`" in st010
    assert "- generic: warning, as by default\n" in st010
    pr003 = runner.invoke(cli, ["explain", "PR003"]).output
    assert "- arnold: warning, as by default; accepts `arnold`, `deep`" in pr003
    ca003 = runner.invoke(cli, ["explain", "CA003"]).output
    assert "- omniverse: error, as by default; accepts `/OmniverseKit_Persp`" in ca003
    va001 = runner.invoke(cli, ["explain", "VA001"]).output
    assert "- moonray: error, as by default; accepts `parameters:moonray:result`" in va001


def test_a_configured_severity_does_not_bring_back_a_rule_a_profile_switches_off(
    tmp_path: Path,
) -> None:
    # PR001 is off under omniverse; severity.PR001 changes its severity where
    # it runs, not whether it runs. The guide says so.
    path = tmp_path / "shot.usda"
    path.write_text(KIT_STAGE, encoding="utf-8")
    out = (
        CliRunner()
        .invoke(
            cli,
            [
                "check",
                "--isolated",
                "--no-cache",
                "--format",
                "json",
                "--config",
                'severity.PR001 = "warning"',
                str(path),
            ],
        )
        .output
    )
    codes = {f["code"] for f in json.loads(out)["files"][0]["findings"]}
    assert "PR001" not in codes
    guide = (Path(__file__).parents[2] / "docs" / "guides" / "profiles.md").read_text()
    assert "does not bring back a rule the profile switches off" in " ".join(guide.split())
