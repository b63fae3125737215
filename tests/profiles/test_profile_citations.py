"""Each name a profile accepts or takes as evidence is cited where that
renderer defines it (R2-5): a page that lists the name, not a later page
that has replaced it."""

from __future__ import annotations

from pathlib import Path

from usdrender_lint.engine import Linter
from usdrender_lint.profiles import PROFILES, Profiler
from usdrender_lint.testing import all_rules


def _prim_type(profile: str, name: str):
    return next(a for a in PROFILES[profile].prim_types if a.name == name)


def test_omni_ultrasonic_cites_the_sensor_schema_version_that_defines_it() -> None:
    # omni.usd.schema.omni_sensors 107.3.0 lists OmniUltrasonic among its typed
    # schemas; the 110.x pages list OmniAcoustic in its place.
    ultrasonic = _prim_type("omniverse", "OmniUltrasonic")
    assert "omni_sensors/107.3.0/" in ultrasonic.source
    assert "OmniAcoustic" in ultrasonic.why


def test_an_omni_ultrasonic_under_render_is_known_to_omniverse(tmp_path: Path) -> None:
    path = tmp_path / "sensor.usda"
    path.write_text(
        '#usda 1.0\ndef Scope "Render"\n{\n    def OmniUltrasonic "Ultrasonic"\n    {\n    }\n}\n',
        encoding="utf-8",
    )

    def codes(profile: str) -> set[str]:
        linter = Linter(all_rules(), profiler=Profiler(lambda f: (profile, "test")))
        return {f.code for f in linter.lint_path(str(path)).findings}

    assert "ST010" in codes("generic")
    assert "ST010" not in codes("omniverse")


def test_the_karma_api_schemas_are_cited() -> None:
    # auto takes an applied Karma* API schema as evidence of Karma: some source
    # must show Houdini applying such schemas to render prims.
    karma = PROFILES["karma"]
    assert karma.api_schemas == ("Karma*",)
    cited = " ".join(karma.evidence_sources)
    for schema in ("KarmaRenderSettingsAPI", "KarmaAOVSettingsAPI"):
        assert schema in cited
