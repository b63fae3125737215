"""Entry point lookup that imports ``importlib.metadata`` only when it must.

``importlib.metadata`` (with the email, zipfile and csv modules it imports) is
about a tenth of the start-up of ``usdrender-lint check`` on one file. Usually
a single distribution registers in our groups (usdrender-lint itself, for the
built-in rules and formatters), and that is cheap to prove: read the same
``entry_points.txt`` files importlib.metadata would read, the same way. Any
other case (a plugin in the group, a zip or egg on ``sys.path``, a finder with
its own distributions, a file we would read differently) is handed to
``importlib.metadata``, so third-party plugins load exactly as before.
Nothing is cached: every call looks at the file system again.

Kept over a plain importlib.metadata call because it is measured to pay:
benchmarks/entry_points.py (both groups in a fresh interpreter: ~33 ms against
~113 ms on a 90-package environment); tests/api/test_entry_point_layouts.py
checks it answers as importlib.metadata on each layout it reads itself.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Sequence
from importlib import import_module
from typing import Any, Protocol

_DIST_SUFFIXES = (".dist-info", ".egg-info")
#: importlib.metadata's entry point value pattern, without extras (those fall back).
_VALUE = re.compile(r"(?P<module>[\w.]+)\s*(:\s*(?P<attr>[\w.]+)\s*)?$")


class EntryPointLike(Protocol):
    name: str
    value: str
    group: str

    def load(self) -> Any: ...


class SimpleEntryPoint:
    """An entry point read from one ``entry_points.txt``; loads like importlib's."""

    __slots__ = ("name", "value", "group")

    def __init__(self, name: str, value: str, group: str) -> None:
        self.name, self.value, self.group = name, value, group

    def load(self) -> Any:
        match = _VALUE.match(self.value)
        assert match is not None  # checked before this object was made
        loaded = import_module(match.group("module"))
        for attr in filter(None, (match.group("attr") or "").split(".")):
            loaded = getattr(loaded, attr)
        return loaded

    def __repr__(self) -> str:
        return f"SimpleEntryPoint(name={self.name!r}, value={self.value!r}, group={self.group!r})"


def entry_points(group: str) -> Sequence[EntryPointLike]:
    """The entry points of ``group``, as ``importlib.metadata.entry_points(group=...)``."""
    try:
        found = _single_registrant(group)
    except (OSError, UnicodeDecodeError, ValueError):
        found = None  # importlib.metadata decides (and raises) as it always did
    if found is not None:
        return found
    from importlib import metadata

    return tuple(metadata.entry_points(group=group))


def _single_registrant(group: str) -> list[SimpleEntryPoint] | None:
    """The group's entry points when exactly one visible distribution declares
    them all in a form read here exactly as importlib.metadata reads it; else None."""
    if _other_finders():
        return None
    seen: set[str] = set()  # importlib.metadata keeps the first distribution of a name
    registrants: list[list[SimpleEntryPoint]] = []
    for entry in sys.path:
        if not isinstance(entry, str) or entry.lower().endswith(".egg"):
            return None
        distributions = _distributions_in(entry or ".")
        if distributions is None:
            return None
        for name, folder in distributions:
            if name in seen:
                continue
            entries = _declared(folder, group)
            if entries is None:
                return None
            if entries:
                registrants.append(entries)
        seen.update(name for name, _ in distributions)
    return registrants[0] if len(registrants) == 1 else None


def _other_finders() -> bool:
    """Whether a finder besides the path finder may find distributions elsewhere."""
    from importlib.machinery import PathFinder

    return any(
        getattr(finder, "find_distributions", None) is not None and finder is not PathFinder
        for finder in sys.meta_path
    )


def _distributions_in(root: str) -> list[tuple[str, str]] | None:
    """The (normalized name, metadata folder) of each distribution in a folder of
    ``sys.path``; None when importlib.metadata would name or order them otherwise."""
    try:
        children = os.listdir(root)
    except OSError:
        return None if os.path.isfile(root) else []  # a zip: importlib.metadata reads inside it
    found: list[tuple[str, str]] = []
    names: set[str] = set()
    for child in children:
        if not child.lower().endswith(_DIST_SUFFIXES):
            continue
        stem, ext = os.path.splitext(child)
        name = _normalize(stem.partition("-")[0])
        if ext not in _DIST_SUFFIXES or not name or name in names:
            return None  # named from its metadata, or an ambiguous order
        names.add(name)
        found.append((name, os.path.join(root, child)))
    return found


def _declared(folder: str, group: str) -> list[SimpleEntryPoint] | None:
    """The group's entry points a distribution declares; None when they are not
    in a form read here exactly as importlib.metadata reads it."""
    path = os.path.join(folder, "entry_points.txt")
    if not os.path.isfile(path):
        return []
    with open(path, encoding="utf-8") as handle:
        return _parse(handle.read(), group)


def _normalize(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower().replace("-", "_")


def _parse(text: str, group: str) -> list[SimpleEntryPoint] | None:
    """``group``'s entries in one ``entry_points.txt``, read line by line as
    importlib.metadata reads it; None for a line it would read differently or
    reject (it parses every group of every distribution)."""
    found = []
    section = None
    for line in map(str.strip, text.splitlines()):
        if not line or line.startswith("#"):
            continue
        if line.startswith("[") and line.endswith("]"):
            section = line.strip("[]")
            continue
        if section is None:
            continue
        name, equals, value = line.partition("=")
        if not equals:
            return None
        if section == group:
            value = value.strip()
            if not _VALUE.match(value):
                return None
            found.append(SimpleEntryPoint(name.strip(), value, group))
    return found
