"""Each rule's SARIF descriptor links its page on the documentation site
(``helpUri``, which code scanning shows): the built-in rules' and UL000's; a
plugin's rule has no page there, so it gets none (nor does the editor link one)."""

from __future__ import annotations

from pathlib import Path

from usdrender_lint.api import Rule, Severity
from usdrender_lint.explain import rule_info
from usdrender_lint.formatters import FormatOptions
from usdrender_lint.formatters.sarif import report_to_sarif
from usdrender_lint.model import DOCS_URL, INTERNAL_ERROR_RULE, Report
from usdrender_lint.registry import build_registry
from usdrender_lint.server.protocol import rule_markdown
from usdrender_lint.server.worker import RuleDoc


class PluginRule(Rule):
    """A plugin's rule.

    ## What it does
    Test rule.
    """

    code = "ZZP001"
    name = "plugin-rule"
    severity = Severity.WARNING


def test_built_in_rules_link_their_page_and_a_plugin_s_none(tmp_path: Path) -> None:
    built_in = next(r for r in build_registry().rules if r.code == "CA004")
    infos = (rule_info(built_in), rule_info(PluginRule), INTERNAL_ERROR_RULE)
    sarif = report_to_sarif(Report((), rules=infos), FormatOptions(), tmp_path)
    links = {r["id"]: r.get("helpUri") for r in sarif["runs"][0]["tool"]["driver"]["rules"]}
    assert links == {
        "CA004": f"{DOCS_URL}reference/rules/CA004-camera-target-not-camera/",
        "UL000": f"{DOCS_URL}reference/rules/UL000-internal-error/",
        "ZZP001": None,
    }
    plugin = RuleDoc("ZZP001", "plugin-rule", (), "warning", "A plugin's rule.", "", "none", None)
    assert "documentation site" not in rule_markdown(plugin)
