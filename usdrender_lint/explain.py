"""A rule's documentation as users read it: ``explain`` prints it, SARIF
carries it as the rule's help, and the documentation site's rule pages are
made from the same parts (its docstring and how each profile treats it)."""

from __future__ import annotations

import dataclasses
import typing

from .api import Rule
from .api.docs import rule_doc, sections
from .model import RuleInfo, rule_doc_url
from .profiles.effective import profile_treatment


def header(rule: type[Rule]) -> str:
    return f"{rule.code} {rule.name} ({rule.severity.value}, fix: {rule.fix_safety})"


def explain_text(rule: type[Rule]) -> str:
    """What ``usdrender-lint explain CODE`` prints (Markdown)."""
    lines = "\n".join(f"- {line}" for line in profile_treatment(rule))
    options = _options_section(rule)
    return f"{header(rule)}\n\n{rule_doc(rule)}{options}\n\n## Under each profile\n{lines}\n"


def _options_section(rule: type[Rule]) -> str:
    """The rule's options, listed from its Options class when its docstring has
    no ``## Options`` section: a plugin rule's options were otherwise nowhere
    that ``explain`` shows."""
    if rule.Options is None or "Options" in sections(rule):
        return ""
    try:
        hints = typing.get_type_hints(rule.Options)
    except Exception:  # noqa: BLE001 - a plugin's unreadable hint: show it as written
        hints = {}
    lines = []
    for field in dataclasses.fields(rule.Options):
        hint = hints.get(field.name, field.type)
        kind = hint.__name__ if isinstance(hint, type) else str(hint).replace("typing.", "")
        if field.default is not dataclasses.MISSING:
            kind += f", default {field.default!r}"
        lines.append(f"- `{field.name.replace('_', '-')}` ({kind})")
    return "\n\n## Options\n" + "\n".join(lines)


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
