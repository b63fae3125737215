"""Reading USD values in the rules without their slow Python iteration."""

from __future__ import annotations

from itertools import islice
from typing import Any


def items(value: Any) -> list[Any]:
    """The elements of a Gf vector or Vt array (or any sized sequence), in order.

    Iterating a Gf vector or Vt array runs until its C++ ``__getitem__`` raises
    IndexError, which costs ~10 us per loop (``min``, ``list``, unpacking and
    ``dict.fromkeys`` all iterate); stopping at its length costs ~1 us.
    """
    return list(islice(value, len(value)))
