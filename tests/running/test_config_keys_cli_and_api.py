"""Every configuration key gives the same findings through the command line and
the Python API: both build one pipeline Request from the same configuration
(issue 12, point 1). Each key is also shown to change the findings (or, for
fail-on and unfixable, the exit status and the fixes), so a key the API ignored
would fail here."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner
from pxr import Usd

import usdrender_lint
from usdrender_lint.cli import cli

SHOT = """#usda 1.0
(
    subLayers = [@./lighting.usda@]
)

def Xform "World"
{
    def Camera "cam"
    {
        float focalLength.timeSamples = {
            1: 50,
            2: -1,
        }
    }
}
"""

LIGHTING = """#usda 1.0

def Scope "Render"
{
    def RenderSettings "Settings" (
        variants = {
            string quality = "draft"
        }
        prepend variantSets = "quality"
    )
    {
        rel camera = </World/cam>
        rel products = </Render/beauty>
        uniform float4 dataWindowNDC = (1, 0, 0, 1)
        variantSet "quality" = {
            "draft" {
            }
            "final" {
                uniform float pixelAspectRatio = 0
            }
        }
    }

    def RenderProduct "beauty"
    {
        rel orderedVars = </Render/color>
    }

    def RenderVar "color"
    {
        uniform string sourceName = "Ci"
    }
}
"""


@pytest.fixture
def shot(tmp_path: Path) -> Path:
    (tmp_path / "shot.usda").write_text(SHOT)
    (tmp_path / "lighting.usda").write_text(LIGHTING)
    return tmp_path


def _cli(path: Path, config: Path, *flags: str) -> tuple[set[tuple], int]:
    result = CliRunner().invoke(
        cli,
        ["check", "--format", "json", "--jobs", "1", "--config", str(config), *flags, str(path)],
    )
    assert result.exit_code in (0, 1), result.output
    findings = {
        (f["code"], f["path"], f["severity"], f["message"], _fix(f["fix"]))
        for entry in json.loads(result.stdout)["files"]
        for f in entry["findings"]
    }
    return findings, result.exit_code


def _fix(fix: dict | None) -> tuple | None:
    return None if fix is None else (fix["description"], fix["safe"])


def _keyed(report: usdrender_lint.Report) -> set[tuple]:
    return {
        (
            f.code,
            f.location.path,
            f.severity.value,
            f.message,
            None if f.fix is None else (f.fix.description, f.fix.safe),
        )
        for f in report.findings
    }


def _api(path: Path, config: Path) -> set[tuple]:
    return _keyed(usdrender_lint.lint_file(path, config=config))


def _api_stage(path: Path, config: Path) -> set[tuple]:
    return _keyed(usdrender_lint.lint_stage(Usd.Stage.Open(str(path)), config=config))


#: Compared with, to show a key changes something (default: no configuration).
BASELINES = {
    "max-variant-combinations": "variants = true",
    "force-exclude": 'extend-exclude = ["lighting.usda"]',
}
#: key -> (TOML of the key, file linted, what the key must change)
KEYS = {
    "select": ('select = ["SE003"]', "lighting.usda", "codes"),
    "ignore": ('ignore = ["SE003"]', "lighting.usda", "codes"),
    "extend-select": ('select = ["SE003"]\nextend-select = ["ST009"]', "lighting.usda", "codes"),
    "severity": ('[severity]\nSE003 = "info"', "lighting.usda", "severities"),
    "per-path-ignores": ('[per-path-ignores]\n"light*" = ["SE003"]', "lighting.usda", "codes"),
    "rules": ("[rules.SE001]\nrequire-authored = true", "lighting.usda", "codes"),
    "roots": ('roots = ["shot.usda"]', "lighting.usda", "codes"),
    "time-sample-cap": ("time-sample-cap = 1", "shot.usda", "codes"),
    # omniverse: PR001 does not apply to RTX products (R2-5).
    "profile": ('profile = "omniverse"', "lighting.usda", "codes"),
    "per-path-profiles": ('[per-path-profiles]\n"light*" = "omniverse"', "lighting.usda", "codes"),
    "variants": ("variants = true", "lighting.usda", "messages"),
    "max-variant-combinations": (
        "variants = true\nmax-variant-combinations = 1", "lighting.usda", "messages"
    ),
    "fail-on": ('fail-on = "never"', "lighting.usda", "exit"),
    "unfixable": ('unfixable = ["SE003"]', "lighting.usda", "none"),
    # where the result cache lives, not what it finds (tests/running/test_result_cache.py)
    "cache-dir": ('cache-dir = "lint-cache"', "lighting.usda", "none"),
    # which files a folder yields, not what a file gives (tests/running/test_discovery.py)
    "exclude": ('exclude = ["lighting.usda"]', "lighting.usda", "none"),
    "extend-exclude": ('extend-exclude = ["lighting.usda"]', "lighting.usda", "none"),
    "respect-gitignore": ("respect-gitignore = false", "lighting.usda", "none"),
    # the extended file's select (tests/running/test_config_extend.py)
    "extend": ('extend = "base.toml"', "lighting.usda", "codes"),
    # a file given that the walk would skip is not linted (tests/running/test_force_exclude.py)
    "force-exclude": (
        'extend-exclude = ["lighting.usda"]\nforce-exclude = true', "lighting.usda", "codes"
    ),
}  # fmt: skip


#: The keys lint_stage does not apply, as documented: it lints the stage it is
#: handed under its own variant selections, and no other stage (roots).
STAGE_DIFFERS = {"variants", "max-variant-combinations", "roots"}


@pytest.mark.parametrize("key", sorted(KEYS))
def test_a_config_key_gives_the_same_findings_through_the_cli_and_the_api(
    shot: Path, key: str
) -> None:
    toml, name, changes = KEYS[key]
    config = shot / ".usdrender-lint.toml"
    config.write_text(toml + "\n")
    (shot / "base.toml").write_text('select = ["SE003"]\n')  # what ``extend`` names
    baseline_config = shot / "defaults.toml"
    baseline_config.write_text(BASELINES.get(key, "") + "\n")
    path = shot / name
    by_cli, status = _cli(path, config)
    assert by_cli == _api(path, config)
    if key not in STAGE_DIFFERS:
        assert by_cli == _api_stage(path, config)
    default, default_status = _cli(path, baseline_config)
    if changes == "codes":
        assert {f[0] for f in by_cli} != {f[0] for f in default}
    elif changes == "severities":
        assert {(f[0], f[2]) for f in by_cli} != {(f[0], f[2]) for f in default}
    elif changes == "messages":
        assert by_cli != default
    elif changes == "exit":
        assert (status, default_status) == (0, 1)


def test_every_config_key_is_covered() -> None:
    """The keys the settings table declares (the configuration parser reads
    exactly those): a new key fails here until it has a row above."""
    from usdrender_lint.settings_table import BY_CONFIG_KEY

    assert set(BY_CONFIG_KEY) == set(KEYS)
