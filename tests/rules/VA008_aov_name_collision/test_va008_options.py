"""VA008's aov-naming option: hdPrman's channel naming, and config validation."""

from __future__ import annotations

from pathlib import Path

import pytest

from usdrender_lint.config import ConfigError, read_config_file
from usdrender_lint.registry import build_registry
from usdrender_lint.rules.vars.va008_aov_name_collision import AovNameCollision
from usdrender_lint.running.pipeline import make_rules
from usdrender_lint.testing import lint_text

# Same sourceName under different prim names: a collision only when channels
# are named after sourceName (hdPrman); the LPE var keeps its prim name there.
SAME_SOURCE = """#usda 1.0

def Scope "Render"
{
    def RenderProduct "Beauty"
    {
        token productName = "beauty.exr"
        rel orderedVars = [</Render/Vars/albedo>, </Render/Vars/albedoHalf>, </Render/Vars/lit>]
    }

    def Scope "Vars"
    {
        def RenderVar "albedo"
        {
            string sourceName = "albedo"
        }

        def RenderVar "albedoHalf"
        {
            uniform token dataType = "color3h"
            string sourceName = "albedo"
        }

        def RenderVar "lit"
        {
            uniform token sourceType = "lpe"
            string sourceName = "albedoHalf"
        }
    }
}
"""


def _messages(rule: AovNameCollision) -> list[str]:
    return [f.message for f in lint_text(SAME_SOURCE, rules=[rule]) if f.code == "VA008"]


def test_prim_names_by_default() -> None:
    assert _messages(AovNameCollision()) == []


def test_source_name_naming_reports_the_hdprman_clash() -> None:
    rule = AovNameCollision(AovNameCollision.Options(aov_naming="sourceName"))
    (message,) = _messages(rule)
    assert "/Render/Vars/albedo and /Render/Vars/albedoHalf" in message
    assert "'albedo'" in message


def _rules(tmp_path: Path, toml: str):
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text(toml, encoding="utf-8")
    return make_rules(build_registry(), read_config_file(config))


def test_option_from_config(tmp_path: Path) -> None:
    rules = _rules(tmp_path, '[rules.aov-name-collision]\naov-naming = "sourceName"\n')
    (rule,) = [r for r in rules if r.code == "VA008"]
    assert rule.options.aov_naming == "sourceName"


@pytest.mark.parametrize(
    "table",
    [
        '[rules.VA008]\naov-naming = "hdPrman"\n',
        "[rules.VA008]\naov-naming = true\n",
        '[rules.VA008]\nnaming = "sourceName"\n',
    ],
)
def test_bad_options_are_config_errors(tmp_path: Path, table: str) -> None:
    with pytest.raises(ConfigError, match="VA008"):
        _rules(tmp_path, table)
