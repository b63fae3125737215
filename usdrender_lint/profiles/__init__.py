"""Renderer profiles (catalog, Revision 2, R2-5): data, one module per renderer.

``PROFILES`` maps each name to its :class:`~.model.Profile`; ``auto`` is not a
profile but the instruction to infer one per RenderSettings (``detect``).
Nothing here imports pxr, so the command line can list profiles cheaply.
"""

from __future__ import annotations

from .arnold import ARNOLD
from .cycles import CYCLES
from .generic import GENERIC
from .karma import KARMA
from .model import Accepted, Behaviour, Profile, ProfileChoice, RuleChange
from .moonray import MOONRAY
from .omniverse import OMNIVERSE
from .renderman import RENDERMAN

AUTO = "auto"

PROFILES: dict[str, Profile] = {
    p.name: p for p in (GENERIC, KARMA, RENDERMAN, ARNOLD, OMNIVERSE, MOONRAY, CYCLES)
}


def Profiler(*args, **kwargs):  # noqa: N802 - the class, loaded with pxr on first use
    """``detect.Profiler``: what the engine calls to decide profiles (imports pxr)."""
    from .detect import Profiler as _Profiler

    return _Profiler(*args, **kwargs)


def get_profile(name: str) -> Profile:
    """The profile of that name; KeyError names the known ones."""
    try:
        return PROFILES[name]
    except KeyError:
        known = ", ".join([AUTO, *PROFILES])
        raise KeyError(f"unknown profile {name!r} (known: {known})") from None


def profile_names() -> list[str]:
    return list(PROFILES)


__all__ = [
    "AUTO",
    "GENERIC",
    "PROFILES",
    "Profiler",
    "Accepted",
    "Behaviour",
    "Profile",
    "ProfileChoice",
    "RuleChange",
    "get_profile",
    "profile_names",
]
