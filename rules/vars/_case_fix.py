"""The fix for a token that matches an allowed one but for case, shared by
VA002 and VA005."""

from __future__ import annotations

from pxr import Usd

from usdrender_lint.api import Fix

from .._corrections import set_value


def _case_fix(attr: Usd.Attribute, correction: str | None, name: str) -> Fix | None:
    if correction is None:
        return None
    return Fix(
        description=f"set {name} to {correction!r}",
        safe=True,
        apply=set_value(attr.GetPath(), correction),
    )
