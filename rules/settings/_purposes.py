"""Purpose token lists, shared by SE009 and SE011."""

from __future__ import annotations

from collections.abc import Sequence


def _duplicates(tokens: Sequence[str]) -> list[str]:
    seen: set[str] = set()
    repeated: list[str] = []
    for token in tokens:
        if token in seen and token not in repeated:
            repeated.append(token)
        seen.add(token)
    return repeated
