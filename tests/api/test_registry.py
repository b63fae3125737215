"""Rule selection: codes, prefixes and names; the most specific selector wins."""

from __future__ import annotations

import pytest

from usdrender_lint.api import Rule, Severity
from usdrender_lint.registry import SelectionError, select_rules


def _rule(code: str, name: str) -> type[Rule]:
    return type(
        name, (Rule,), {"code": code, "name": name, "severity": Severity.ERROR, "__doc__": "x"}
    )


RULES = [
    _rule("CA001", "camera-unset"),
    _rule("CA004", "camera-target-not-camera"),
    _rule("SE003", "data-window-malformed"),
    _rule("SE007", "instantaneous-shutter-deprecated"),
]


@pytest.mark.parametrize(
    ("select", "ignore", "expected"),
    [
        (None, [], ["CA001", "CA004", "SE003", "SE007"]),
        (["CA"], [], ["CA001", "CA004"]),
        (["ca004"], [], ["CA004"]),
        (["data-window-malformed"], [], ["SE003"]),
        (None, ["SE"], ["CA001", "CA004"]),
        (["SE"], ["SE007"], ["SE003"]),
        (["SE007"], ["SE"], ["SE007"]),  # the full code is more specific than the prefix
        (["CA004"], ["CA004"], []),  # a tie goes to ignore
        (["ALL"], ["instantaneous-shutter-deprecated", "C"], ["SE003"]),
    ],
)
def test_selection_table(select, ignore, expected) -> None:
    assert [r.code for r in select_rules(RULES, select, ignore)] == expected


def test_extend_select_adds_to_a_selection() -> None:
    chosen = select_rules(RULES, ["CA001"], [], extend_select=["SE003"])
    assert [r.code for r in chosen] == ["CA001", "SE003"]


def test_unknown_selector_raises() -> None:
    with pytest.raises(SelectionError, match="'PX' matches no rule"):
        select_rules(RULES, ["PX"], [])
