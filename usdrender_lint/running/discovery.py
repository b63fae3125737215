"""Which files a run lints: the paths given, folders expanded recursively into
USD files (sorted), each file once. A folder that cannot be listed is kept in
the list in place of its files, so the engine reports it (``permission
denied``) instead of the run skipping it."""

from __future__ import annotations

import os
from collections.abc import Iterable

from ..engine import USD_EXTENSIONS


def collect_files(paths: Iterable[str], empty: list[str] | None = None) -> list[str]:
    """Expand directories recursively into USD files (sorted); keep files,
    missing paths and folders that cannot be listed as given so the engine
    reports them. The folders that hold no USD file are added to ``empty``."""
    files: list[str] = []
    for path in paths:
        if os.path.isdir(path):
            found = _walk(path)
            if not found and empty is not None:
                empty.append(path)
            files.extend(found)
        else:
            files.append(path)
    seen: set[str] = set()
    unique = []
    for f in files:
        key = os.path.normpath(f)
        if key not in seen:
            seen.add(key)
            unique.append(f)
    return unique


def _walk(top: str) -> list[str]:
    found: list[str] = []

    def unlisted(error: OSError) -> None:
        found.append(error.filename if isinstance(error.filename, str) else top)

    for folder, dirs, names in os.walk(top, onerror=unlisted, followlinks=False):
        dirs.sort()
        found.extend(os.path.join(folder, n) for n in names if n.lower().endswith(USD_EXTENSIONS))
    return sorted(found)
