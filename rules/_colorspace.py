"""Colour-space names as usd-core 26.11 understands them (catalog, Ambiguous semantics 6).

Valid = ``Usd.ColorSpaceAPI.IsValidColorSpaceName``: the ``Gf.ColorSpaceNames``
tokens, the display-name aliases ``Gf.ColorSpace`` accepts (``ACEScg``), and
custom spaces a ``ColorSpaceDefinitionAPI`` declares on the prim or an ancestor.
"""

from __future__ import annotations

import re

from pxr import Gf, Usd

from usdrender_lint.api import record

#: The canonical built-in tokens, in Gf's order (aliases such as
#: ``LinearDisplayP3`` name the same token, hence the de-duplication).
CANONICAL_NAMES: tuple[str, ...] = tuple(
    dict.fromkeys(
        str(getattr(Gf.ColorSpaceNames, attr))
        for attr in dir(Gf.ColorSpaceNames)
        if not attr.startswith("_")
    )
)
#: Spaces that designate "no colour" rather than a working space.
_DATA_LIKE = frozenset({"data", "raw", "identity", "unknown"})


@record(frozen=True)
class ResolvedColorSpace:
    """A valid colour-space name and the transfer function it stands for."""

    name: str
    #: The canonical token for a built-in or alias, the definition's name for a custom space.
    canonical: str
    gamma: float
    linear_bias: float
    is_data: bool
    #: Where the ColorSpaceDefinitionAPI declaring a custom space lives.
    defined_on: str | None = None

    @property
    def is_linear(self) -> bool:
        return self.gamma == 1 and self.linear_bias == 0

    @property
    def is_data_like(self) -> bool:
        return self.is_data or self.canonical in _DATA_LIKE


def is_valid_name(prim: Usd.Prim, name: str, cache: Usd.ColorSpaceCache) -> bool:
    return Usd.ColorSpaceAPI.IsValidColorSpaceName(prim, name, cache)


def _custom_definition(prim: Usd.Prim, name: str) -> Usd.ColorSpaceDefinitionAPI | None:
    """The nearest ColorSpaceDefinitionAPI on the prim or an ancestor naming ``name``."""
    while prim and not prim.IsPseudoRoot():
        for definition in Usd.ColorSpaceDefinitionAPI.GetAll(prim):
            if definition.GetNameAttr().Get() == name:
                return definition
        prim = prim.GetParent()
    return None


def resolve(prim: Usd.Prim, name: str, cache: Usd.ColorSpaceCache) -> ResolvedColorSpace | None:
    """What a colour-space name means for ``prim``, or None when it is not valid."""
    if not is_valid_name(prim, name, cache):
        return None
    definition = _custom_definition(prim, name)
    if definition is not None:
        space = definition.ComputeColorSpaceFromDefinitionAttributes()
        where = str(definition.GetPrim().GetPath())
        return ResolvedColorSpace(
            name, name, space.GetGamma(), space.GetLinearBias(), space.IsData(), where
        )
    space = Gf.ColorSpace(name)
    return ResolvedColorSpace(
        name, space.GetName(), space.GetGamma(), space.GetLinearBias(), space.IsData()
    )


def nearest_names(name: str, count: int = 3) -> list[str]:
    """Canonical tokens closest to a misspelt or foreign name.

    An OCIO-style name such as ``ACES - ACEScg`` often embeds a name Gf knows
    (``ACEScg``); its canonical token comes first.
    """
    embedded = [
        Gf.ColorSpace(part).GetName()
        for part in re.split(r"\s+-\s+|[/:|]", name)
        if part.strip() and Gf.ColorSpace.IsValid(part.strip())
    ]
    lowered = {c.lower(): c for c in CANONICAL_NAMES}
    import difflib  # only to suggest a name for an unknown one

    close = difflib.get_close_matches(name.lower(), list(lowered), n=count, cutoff=0.4)
    return list(dict.fromkeys(embedded + [lowered[m] for m in close]))[:count]


def linear_counterpart(space: ResolvedColorSpace) -> str | None:
    """The built-in linear space with the same primaries and white point."""
    if space.defined_on is not None:
        return None
    primaries = Gf.ColorSpace(space.canonical).GetPrimariesAndWhitePoint()
    for candidate in CANONICAL_NAMES:
        other = Gf.ColorSpace(candidate)
        if (
            other.GetGamma() == 1
            and other.GetLinearBias() == 0
            and not other.IsData()
            and other.GetPrimariesAndWhitePoint() == primaries
        ):
            return candidate
    return None
