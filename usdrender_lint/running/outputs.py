"""What a run may write: never a report, a baseline or a picture onto a file
the same run reads (``check --output shot.usda shot.usda`` would replace the
shot with its own report)."""

from __future__ import annotations

import os
import stat
from collections.abc import Iterable

#: Layer file suffixes: an existing file so named is a layer, never a report.
LAYER_SUFFIXES = (".usd", ".usda", ".usdc", ".usdz")


class OutputOnInput(ValueError):
    """An output names a file the run reads: one line, exit 2."""


def refuse_inputs(outputs: Iterable[tuple[str | None, str]], inputs: Iterable[str]) -> None:
    """Raise OutputOnInput when an output (``(path, what)``: None for none)
    is an existing regular file that is one of ``inputs`` (the same file, by
    any name or link) or a USD layer (which a stage of the run may compose)."""
    named = [(path, what, _identity(path)) for path, what in outputs if path]
    named = [(path, what, identity) for path, what, identity in named if identity]
    if not named:
        return
    read: dict[tuple[int, int], str] = {}
    for path in inputs:
        identity = _identity(path)
        if identity:
            read.setdefault(identity, path)
    for path, what, identity in named:
        if identity in read:
            same = "" if read[identity] == path else f" ({read[identity]})"
            raise OutputOnInput(
                f"{path}: is an input of this run{same}; refusing to write {what} onto it: "
                "choose another file"
            )
        if path.lower().endswith(LAYER_SUFFIXES):
            raise OutputOnInput(
                f"{path}: is a USD layer; refusing to write {what} onto it: choose another file"
            )


def refuse_one_file_twice(outputs: Iterable[tuple[str | None, str]]) -> None:
    """Raise OutputOnInput when two outputs (``(path, what)``) name one file:
    the second write would silently replace the first."""
    named: dict[str, tuple[str, str]] = {}
    for path, what in outputs:
        if not path:
            continue
        key = os.path.realpath(path)
        if key in named:
            first, first_what = named[key]
            same = "" if first == path else f" (as {first})"
            raise OutputOnInput(
                f"{path}: is named for both {first_what}{same} and {what}; choose a file for each"
            )
        named[key] = (path, what)


def _identity(path: str) -> tuple[int, int] | None:
    """(device, inode) of the regular file at ``path`` (links followed), or None."""
    try:
        info = os.stat(path)
    except (OSError, ValueError):
        return None
    return (info.st_dev, info.st_ino) if stat.S_ISREG(info.st_mode) else None
