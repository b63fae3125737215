"""resolve.items: the elements of USD vectors and arrays, read without
running their iteration into the IndexError that ends it."""

from __future__ import annotations

import math

import pytest
from pxr import Gf, Vt

from usdrender_lint.api.resolve import is_finite, items


@pytest.mark.parametrize(
    "value",
    [
        Gf.Vec2i(1920, 0),
        Gf.Vec2f(0.1, math.inf),
        Gf.Vec4f(0, 0, 1, 1),
        Vt.TokenArray(["default", "render", "render"]),
        Vt.TokenArray([]),
        Vt.StringArray(["a", ""]),
        (1, 2, 3),
        "abc",
    ],
)
def test_items_are_the_iterated_elements(value) -> None:
    assert items(value) == list(value)


def test_nan_components_are_kept() -> None:
    found = items(Gf.Vec4f(math.nan, 0, 1, 1))
    assert len(found) == 4 and math.isnan(found[0])


class _Counted:
    """A sequence that records every index asked for, like a Vt array whose
    reads past the end raise IndexError."""

    def __init__(self, values: list[int]) -> None:
        self.values = values
        self.asked: list[int] = []

    def __len__(self) -> int:
        return len(self.values)

    def __getitem__(self, index: int) -> int:
        self.asked.append(index)
        return self.values[index]


def test_items_never_reads_past_the_end() -> None:
    sequence = _Counted([3, 4])
    assert items(sequence) == [3, 4]
    assert sequence.asked == [0, 1]


@pytest.mark.parametrize(
    ("value", "finite"),
    [
        (1, True),
        (True, True),
        (-2.5, True),
        (math.nan, False),
        (-math.inf, False),
        (Gf.Vec2f(1, 2), True),
        (Gf.Vec4f(0, 0, math.nan, 1), False),
        (Gf.Vec2d(math.inf, 0), False),
        (Vt.FloatArray([0.5, 1]), True),
        ([1.0, math.nan], False),
        ((x for x in (1.0, 2.0)), True),  # iterable without a length
        (iter([math.inf]), False),
        ("ab", False),  # text is not a number
        (None, False),
    ],
)
def test_is_finite_reads_scalars_vectors_and_sequences(value, finite) -> None:
    """resolve.is_finite: scalars directly, vectors up to their length (the same
    answers as iterating them)."""
    assert is_finite(value) is finite
