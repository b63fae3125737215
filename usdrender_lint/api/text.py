"""Values in messages, bounded before they are formatted.

The engine cuts every message at MAX_MESSAGE_CHARS; a rule that quotes an
array must not format all of it first (a two-million-entry token array costs
seconds to turn into text that is then thrown away). :func:`listing` renders
only the elements that fit and says how many it left out.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from itertools import islice
from typing import Any

#: Longest finding message kept (the engine's bounded_message).
MAX_MESSAGE_CHARS = 2000
#: Longest quote of a value inside a message, so that what the message says
#: about the value still fits after it.
MAX_VALUE_CHARS = 500


def listing(
    values: Iterable[Any],
    render: Callable[[Any], str] = str,
    separator: str = ", ",
    limit: int = MAX_VALUE_CHARS,
) -> str:
    """The values rendered and joined by ``separator``, as many as fit in
    ``limit`` characters; the rest of a sized collection are counted
    (``a, b, … (1,998 more)``), those of an iterator only marked (``a, b, …``).
    A Vt array or Gf vector is read only as far as it is shown."""
    total = len(values) if hasattr(values, "__len__") else None  # type: ignore[arg-type]
    source = islice(values, total) if total is not None else iter(values)
    parts: list[str] = []
    used = 0
    for value in source:
        text = render(value)
        used += len(text) + (len(separator) if parts else 0)
        if used > limit and parts:
            more = f" ({total - len(parts):,} more)" if total is not None else ""
            return f"{separator.join(parts)}{separator}…{more}"
        parts.append(text)
    return separator.join(parts)
