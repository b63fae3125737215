"""SE001's require-authored option: off by default, reports an unauthored
resolution when set, and a mistyped or unknown option is a config error."""

from __future__ import annotations

import pytest

from usdrender_lint.config import ConfigError, Settings
from usdrender_lint.registry import build_registry
from usdrender_lint.rules.settings.se001_resolution_non_positive import ResolutionNonPositive
from usdrender_lint.running.pipeline import make_rules
from usdrender_lint.testing import lint_text

UNAUTHORED_RESOLUTION = """#usda 1.0
def RenderSettings "S"
{
}
"""


def _paths(settings: Settings) -> list[str | None]:
    rules = make_rules(build_registry(), settings)
    return [
        f.location.path for f in lint_text(UNAUTHORED_RESOLUTION, rules=rules, select=["SE001"])
    ]


def test_option_is_off_by_default_and_reports_when_set() -> None:
    assert _paths(Settings()) == []
    settings = Settings(rule_options={"resolution-non-positive": {"require-authored": True}})
    assert len(_paths(settings)) == 1


@pytest.mark.parametrize(
    "options",
    [
        {"require-authored": "yes"},  # mistyped
        {"require_authored": 1},  # mistyped
        {"require-authorized": True},  # unknown
    ],
)
def test_bad_se001_option_is_a_config_error(options: dict) -> None:
    with pytest.raises(ConfigError, match="resolution-non-positive"):
        make_rules(build_registry(), Settings(rule_options={"resolution-non-positive": options}))


def test_option_default() -> None:
    assert ResolutionNonPositive().options.require_authored is False
