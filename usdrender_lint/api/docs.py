"""Rule documentation: the rule's docstring is the doc (ruff's sections)."""

from __future__ import annotations

import inspect
import re

from .rule import DOC_SECTIONS, Rule

_HEADING = re.compile(r"^##\s+(.+?)\s*$", re.MULTILINE)
_CODE_BLOCK = re.compile(r"```(\w*)\n(.*?)```", re.DOTALL)
_NAMED_BLOCK = re.compile(r"```usda ([\w.-]+\.usda)\n(.*?)```", re.DOTALL)


def rule_doc(rule: type[Rule]) -> str:
    return inspect.cleandoc(rule.documentation())


def sections(rule: type[Rule]) -> dict[str, str]:
    """The docstring's ``## Heading`` sections, by heading."""
    doc = rule_doc(rule)
    found: dict[str, str] = {}
    headings = list(_HEADING.finditer(doc))
    for current, following in zip(headings, [*headings[1:], None], strict=True):
        end = following.start() if following else len(doc)
        found[current.group(1)] = doc[current.end() : end].strip()
    return found


def missing_sections(rule: type[Rule]) -> list[str]:
    present = sections(rule)
    return [name for name in DOC_SECTIONS if not present.get(name)]


def code_blocks(text: str, language: str = "usda") -> list[str]:
    return [body for lang, body in _CODE_BLOCK.findall(text) if lang == language]


def supporting_layers(text: str) -> dict[str, str]:
    """Blocks fenced as ```` ```usda <file>.usda ````: layers an example sublayers
    or references, written beside it (not examples themselves)."""
    return dict(_NAMED_BLOCK.findall(text))
