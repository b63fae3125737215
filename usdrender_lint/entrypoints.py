"""Entry point lookup that imports ``importlib.metadata`` only when it must.

``importlib.metadata`` (with the email, zipfile and csv modules it imports) is
about a tenth of the start-up of ``usdrender-lint check`` on one file. Usually
a single distribution registers in our groups (usdrender-lint itself, for the
built-in rules and formatters), and that is cheap to prove: read the same
``entry_points.txt`` files importlib.metadata would read, the same way. Any
other case (a plugin in the group, a zip or egg on ``sys.path``, a finder with
its own distributions, a file we would read differently) is handed to
``importlib.metadata``, so third-party plugins load exactly as before.
Nothing is cached: every call looks at the file system again, but inside
:func:`read_once` (a command line run), where the first lookup reads every
group and the next answer from that reading.

Kept over a plain importlib.metadata call because it is measured to pay:
benchmarks/entry_points.py (both groups in a fresh interpreter: ~33 ms against
~113 ms on a 90-package environment); tests/api/test_entry_point_layouts.py
checks it answers as importlib.metadata on each layout it reads itself.
"""

from __future__ import annotations

import contextvars
import os
import re
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
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
    reading = _READING.get()
    return (reading if reading is not None else _Reading()).group(group)


@contextmanager
def read_once() -> Iterator[None]:
    """Inside, the distributions' entry points are read at the first lookup,
    every group at once, and later lookups answer from that reading: a command
    asks for the rules' and the formatters', each read cost as much as both."""
    token = _READING.set(_Reading())
    try:
        yield
    finally:
        _READING.reset(token)


class _Reading:
    """One reading of every distribution's entry points (by group), made at the
    first question; importlib.metadata's too, once, when a group needs it."""

    def __init__(self) -> None:
        self._declared: dict[str, list[list[tuple[str, str]]]] | None = None
        self._metadata: Any = None

    def group(self, group: str) -> Sequence[EntryPointLike]:
        if self._declared is None:
            try:
                self._declared = _declarations()
            except (OSError, UnicodeDecodeError, ValueError):
                self._declared = {}  # importlib.metadata decides (and raises) as it always did
        found = _single_registrant_of(self._declared, group)
        if found is not None:
            return found
        if self._metadata is None:
            from importlib import metadata

            self._metadata = metadata.entry_points()
        return tuple(self._metadata.select(group=group))


#: The reading of the running read_once, if any.
_READING: contextvars.ContextVar[_Reading | None] = contextvars.ContextVar(
    "usdrender_lint_entry_points", default=None
)


def _single_registrant(group: str) -> list[SimpleEntryPoint] | None:
    """The group's entry points when exactly one visible distribution declares
    them all in a form read here exactly as importlib.metadata reads it; else None."""
    return _single_registrant_of(_declarations(), group)


def _single_registrant_of(
    declared: dict[str, list[list[tuple[str, str]]]], group: str
) -> list[SimpleEntryPoint] | None:
    registrants = declared.get(group, [])
    if len(registrants) != 1 or not all(_VALUE.match(value) for _, value in registrants[0]):
        return None
    return [SimpleEntryPoint(name, value, group) for name, value in registrants[0]]


def _declarations() -> dict[str, list[list[tuple[str, str]]]]:
    """Each group's (name, value) entries of each visible distribution that declares
    some, in importlib.metadata's order; {} when importlib.metadata must read them
    (or it would read a file otherwise)."""
    if _other_finders():
        return {}
    seen: set[str] = set()  # importlib.metadata keeps the first distribution of a name
    declared: dict[str, list[list[tuple[str, str]]]] = {}
    for entry in sys.path:
        if not isinstance(entry, str) or entry.lower().endswith(".egg"):
            return {}
        distributions = _distributions_in(entry or ".")
        if distributions is None:
            return {}
        for name, folder in distributions:
            if name in seen:
                continue
            groups = _declared(folder)
            if groups is None:
                return {}
            for group, entries in groups.items():
                if entries:
                    declared.setdefault(group, []).append(entries)
        seen.update(name for name, _ in distributions)
    return declared


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


def _declared(folder: str) -> dict[str, list[tuple[str, str]]] | None:
    """The (name, value) entries a distribution declares, by group; None when
    they are not in a form read here exactly as importlib.metadata reads it."""
    path = os.path.join(folder, "entry_points.txt")
    if not os.path.isfile(path):
        return {}
    with open(path, encoding="utf-8") as handle:
        return _parse(handle.read())


def _normalize(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower().replace("-", "_")


def _parse(text: str) -> dict[str, list[tuple[str, str]]] | None:
    """The (name, value) entries of one ``entry_points.txt`` by group, read line
    by line as importlib.metadata reads it; None for a line it would read
    differently or reject (it parses every group of every distribution). A
    value is checked against importlib.metadata's pattern when its group is asked."""
    found: dict[str, list[tuple[str, str]]] = {}
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
        found.setdefault(section, []).append((name.strip(), value.strip()))
    return found
