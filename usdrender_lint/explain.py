"""A rule's documentation as users read it: ``explain`` prints it, SARIF
carries it as the rule's help, and the documentation site's rule pages are
made from the same parts (its docstring and how each profile treats it)."""

from __future__ import annotations

import contextlib
import dataclasses
import re
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
    lines = []
    for option in rule_options(rule):
        kind = option.kind
        if option.default is not dataclasses.MISSING:
            kind += f", default {option.default!r}"
        lines.append(f"- `{option.name}` ({kind})")
    return "\n\n## Options\n" + "\n".join(lines)


class RuleOption(typing.NamedTuple):
    """One option of a rule, as ``explain`` and ``config`` describe it."""

    #: As a configuration file spells it (``require-authored``).
    name: str
    #: Its type, as the rule's Options class declares it.
    kind: str
    #: Its default (``dataclasses.MISSING`` when it has none).
    default: object
    #: Its entry in the docstring's ``## Options`` section, after the name and
    #: the parenthesis ("also report a RenderSettings..."); "" when it has none.
    doc: str


def rule_options(rule: type[Rule]) -> list[RuleOption]:
    """The fields of the rule's Options class, with what its docstring says of each."""
    if rule.Options is None:
        return []
    try:
        hints = typing.get_type_hints(rule.Options)
    except Exception:  # noqa: BLE001 - a plugin's unreadable hint: show it as written
        hints = {}
    fields = dataclasses.fields(rule.Options)
    names = [field.name.replace("_", "-") for field in fields]
    documented = _documented_options(sections(rule).get("Options", ""), names)
    options = []
    for field, name in zip(fields, names, strict=True):
        hint = hints.get(field.name, field.type)
        kind = hint.__name__ if isinstance(hint, type) else str(hint).replace("typing.", "")
        default: object = field.default
        if default is dataclasses.MISSING and field.default_factory is not dataclasses.MISSING:
            # A plugin's factory that fails leaves its default unsaid.
            with contextlib.suppress(Exception):
                default = field.default_factory()
        options.append(RuleOption(name, kind, default, documented.get(name, "")))
    return options


def _documented_options(section: str, names: list[str]) -> dict[str, str]:
    """Each option's entry in an ``## Options`` section: a line that starts with
    its name in backticks (after a list's "- "), to the next such line."""
    if not names or not section:
        return {}
    spelt = "|".join(re.escape(name) + "|" + re.escape(name.replace("-", "_")) for name in names)
    entries = list(re.finditer(rf"^(?:[-*]\s+)?`({spelt})`", section, re.MULTILINE))
    found: dict[str, str] = {}
    ends = [following.start() for following in entries[1:]] + [len(section)]
    for entry, end in zip(entries, ends, strict=True):
        text = " ".join(section[entry.end() : end].split())
        if text.startswith("("):  # the type and default: the Options class says them
            text = text[_closing(text) + 1 :].lstrip()
        found[entry.group(1).replace("_", "-")] = text.removeprefix(":").strip()
    return found


def _closing(text: str) -> int:
    """Where the parenthesis that opens ``text`` closes (its end when it does not)."""
    depth = 0
    for index, char in enumerate(text):
        depth += {"(": 1, ")": -1}.get(char, 0)
        if depth == 0:
            return index
    return len(text)


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
