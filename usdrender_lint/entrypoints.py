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
    from importlib.machinery import PathFinder

    for finder in sys.meta_path:
        if getattr(finder, "find_distributions", None) is not None and finder is not PathFinder:
            return None
    seen: set[str] = set()  # importlib.metadata keeps the first distribution of a name
    registrants: list[list[SimpleEntryPoint]] = []
    for entry in sys.path:
        if not isinstance(entry, str) or entry.lower().endswith(".egg"):
            return None
        root = entry or "."
        try:
            children = os.listdir(root)
        except OSError:
            if os.path.isfile(root):
                return None  # a zip: importlib.metadata reads inside it
            continue
        here: set[str] = set()
        for child in children:
            if not child.lower().endswith(_DIST_SUFFIXES):
                continue
            stem, ext = os.path.splitext(child)
            name = _normalize(stem.partition("-")[0])
            if ext not in _DIST_SUFFIXES or not name or name in here:
                return None  # named from its metadata, or an ambiguous order
            here.add(name)
            if name in seen:
                continue
            path = os.path.join(root, child, "entry_points.txt")
            if os.path.isfile(path):
                with open(path, encoding="utf-8") as handle:
                    entries = _parse(handle.read(), group)
                if entries is None:
                    return None
                if entries:
                    registrants.append(entries)
        seen |= here
    return registrants[0] if len(registrants) == 1 else None


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
