"""How values and token lists read in SE messages."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from pxr import Vt

from usdrender_lint.api.text import listing


def _fmt(value: Any) -> str:
    """A value as it reads in a message: vectors as tuples, floats trimmed;
    only as much of an array as a message can hold is formatted."""
    if value is None:
        return "no value"
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, float):
        return f"{value:g}"
    try:
        first = next(iter(value), None)
    except TypeError:
        return str(value)
    if isinstance(value, Vt.TokenArray) or (first is not None and isinstance(first, str)):
        return "[" + listing(value, lambda v: f'"{v}"') + "]"
    return "(" + listing(value, _fmt) + ")"


def _quoted(tokens: Sequence[str]) -> str:
    return listing(tokens, lambda t: f'"{t}"')
