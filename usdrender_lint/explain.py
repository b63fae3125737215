"""A rule's documentation as users read it: ``explain`` prints it, SARIF
carries it as the rule's help, and the documentation site's rule pages are
made from the same parts (its docstring and how each profile treats it)."""

from __future__ import annotations

from .api import Rule
from .api.docs import rule_doc
from .model import RuleInfo, rule_doc_url
from .profiles.effective import profile_treatment


def header(rule: type[Rule]) -> str:
    return f"{rule.code} {rule.name} ({rule.severity.value}, fix: {rule.fix_safety})"


def explain_text(rule: type[Rule]) -> str:
    """What ``usdrender-lint explain CODE`` prints (Markdown)."""
    lines = "\n".join(f"- {line}" for line in profile_treatment(rule))
    return f"{header(rule)}\n\n{rule_doc(rule)}\n\n## Under each profile\n{lines}\n"


#: A rule class and its docstring never change, and every report lists them.
_INFO: dict[type[Rule], RuleInfo] = {}


def rule_info(rule: type[Rule]) -> RuleInfo:
    """The rule as a report describes it, its documentation in full (built
    once per process)."""
    info = _INFO.get(rule)
    if info is None:
        info = _INFO[rule] = RuleInfo(
            code=rule.code,
            name=rule.name,
            severity=rule.severity,
            summary=rule.summary(),
            doc=explain_text(rule),
            fix=rule.fix_safety,
            # Only the rules this package ships have pages on its documentation site.
            url=rule_doc_url(rule.code, rule.name) if _built_in(rule) else None,
        )
    return info


def _built_in(rule: type[Rule]) -> bool:
    return rule.__module__.startswith(__name__.rpartition(".")[0] + ".rules.")
