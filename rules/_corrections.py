"""Value corrections shared by the PR and VA fixes: case-only token matches
and the fix that authors a corrected value."""

from __future__ import annotations

from collections.abc import Callable, Iterable

from pxr import Sdf, Usd


def unique_case_match(value: str, candidates: Iterable[str]) -> str | None:
    """The one candidate equal to ``value`` ignoring case (and differing from
    it), or None when there is no such candidate or more than one."""
    matches = {c for c in candidates if c.lower() == value.lower() and c != value}
    return matches.pop() if len(matches) == 1 else None


def set_value(attr_path: Sdf.Path, value: object) -> Callable[[Usd.Stage], None]:
    """A fix ``apply`` that authors ``value`` on the attribute in the edit target."""

    def apply(stage: Usd.Stage) -> None:
        stage.GetAttributeAtPath(attr_path).Set(value)

    return apply
