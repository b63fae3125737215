"""How values and token lists read in SE messages."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from pxr import Vt


def _fmt(value: Any) -> str:
    """A value as it reads in a message: vectors as tuples, floats trimmed."""
    if value is None:
        return "no value"
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, float):
        return f"{value:g}"
    try:
        items = list(value)
    except TypeError:
        return str(value)
    if value and all(isinstance(v, str) for v in items):
        return "[" + ", ".join(f'"{v}"' for v in items) + "]"
    if not items and isinstance(value, Vt.TokenArray):
        return "[]"
    return "(" + ", ".join(_fmt(v) for v in items) + ")"


def _quoted(tokens: Sequence[str]) -> str:
    return ", ".join(f'"{t}"' for t in tokens)
