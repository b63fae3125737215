"""Brace alternatives in the configuration's globs and patterns: one reading
for every key that takes them (``per-path-ignores``, ``per-path-profiles``,
``exclude``, ``extend-exclude``), as ruff's globs (globset) read ``{a,b}``."""

from __future__ import annotations

import re
from collections.abc import Iterable

#: The innermost ``{...}`` holding a comma: its alternatives are expanded first.
_BRACES = r"\{([^{}]*,[^{}]*)\}"  # compiled when first used, not at start-up


def expand_braces(pattern: str) -> list[str]:
    """``"{a,b}/*.usda"`` -> ``["a/*.usda", "b/*.usda"]`` (nested groups too);
    fnmatch and gitignore patterns have no alternation, which globset has."""
    found = re.search(_BRACES, pattern) if "{" in pattern else None
    if found is None:
        # An alternative ending in '/' ("{a,b/}/*.usda") leaves a '//'.
        return [re.sub(r"(?<=.)/{2,}", "/", pattern)]
    head, tail = pattern[: found.start()], pattern[found.end() :]
    return [
        expanded
        for choice in found.group(1).split(",")
        for expanded in expand_braces(head + choice + tail)
    ]


def expand_all(patterns: Iterable[str]) -> list[str]:
    """Each pattern's alternatives, in order (a pattern without braces as it is)."""
    return [each for pattern in patterns for each in expand_braces(pattern)]
