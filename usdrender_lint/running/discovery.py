"""Which files a run lints: the paths given, folders expanded recursively into
USD files (sorted), each file once."""

from __future__ import annotations

import os
from collections.abc import Iterable

from ..engine import USD_EXTENSIONS


def collect_files(paths: Iterable[str]) -> list[str]:
    """Expand directories recursively into USD files (sorted); keep files and
    missing paths as given so the engine reports them."""
    files: list[str] = []
    for path in paths:
        if os.path.isdir(path):
            found: list[str] = []
            for folder, dirs, names in os.walk(path, followlinks=False):
                dirs.sort()
                found.extend(
                    os.path.join(folder, n) for n in names if n.lower().endswith(USD_EXTENSIONS)
                )
            files.extend(sorted(found))
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
