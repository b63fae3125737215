"""SE013's flag-data-spaces option: off by default, reports a data space
("raw") when set; an unknown option is a config error."""

from __future__ import annotations

import pytest

from usdrender_lint.config import ConfigError, Settings
from usdrender_lint.registry import build_registry
from usdrender_lint.rules.settings.se013_rendering_color_space_not_linear import (
    RenderingColorSpaceNotLinear,
)
from usdrender_lint.running.pipeline import make_rules
from usdrender_lint.testing import lint_text

RAW_SPACE = """#usda 1.0
def RenderSettings "S"
{
    uniform token renderingColorSpace = "raw"
}
"""


def _paths(settings: Settings) -> list[str | None]:
    rules = make_rules(build_registry(), settings)
    return [f.location.path for f in lint_text(RAW_SPACE, rules=rules, select=["SE013"])]


def test_option_is_off_by_default_and_reports_when_set() -> None:
    assert _paths(Settings()) == []
    assert len(_paths(Settings(rule_options={"SE013": {"flag-data-spaces": True}}))) == 1


def test_bad_se013_option_is_a_config_error() -> None:
    with pytest.raises(ConfigError, match="unknown option 'strict'"):
        make_rules(build_registry(), Settings(rule_options={"SE013": {"strict": True}}))


def test_option_default() -> None:
    assert RenderingColorSpaceNotLinear().options.flag_data_spaces is False
