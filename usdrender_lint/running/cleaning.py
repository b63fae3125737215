"""``usdrender-lint clean``: which result caches a check of some paths uses,
found as the check finds them, and their removal (result_cache.clear)."""

from __future__ import annotations

import os
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

from ..config import ConfigError, config_file_in, read_config_file, with_inline
from ..paths import display_path
from ..records import record
from .pipeline import Request, resolve_settings
from .result_cache import CACHE_DIR_NAME, Cleared, cache_folder, clear, is_cache_folder


@record(frozen=True)
class Cleaning:
    """What ``clean`` did: the caches it cleared, and a note for each folder it
    left alone (a folder of the cache's name that is not one, a configuration
    it could not read)."""

    cleared: tuple[Cleared, ...]
    notes: tuple[str, ...]
    #: The paths given that do not exist (the others are cleaned all the same).
    missing: tuple[str, ...] = ()


def clean(
    paths: Sequence[str],
    *,
    cache_dir: str | os.PathLike[str] | None = None,
    config: str | None = None,
    config_overrides: Sequence[str | Mapping[str, Any]] = (),
    isolated: bool = False,
) -> Cleaning:
    """Remove the result caches ``check PATHS`` would use with the same
    options: the folder of the configuration in effect at each path (or
    ``cache_dir``), and below each folder given every cache of a nested
    configuration and every folder of the cache's default name (links not
    followed). A ``cache_dir`` that is not a cache folder raises
    :class:`~.result_cache.ForeignFolder`; a ConfigError is the configuration's."""
    notes: list[str] = []
    cleared: list[Cleared] = []
    seen: set[str] = set()
    missing = tuple(p for p in paths if not os.path.lexists(p))
    paths = [p for p in paths if p not in missing]
    for folder, named in _candidates(paths, cache_dir, config, config_overrides, isolated, notes):
        key = os.path.realpath(folder)
        if key in seen or not os.path.lexists(folder):
            continue
        seen.add(key)
        if is_cache_folder(folder):
            cleared.append(clear(folder))
        elif _holds_anything(folder):  # an empty folder is no cache yet
            if named:
                clear(folder)  # raises ForeignFolder, as check refuses such a folder
            shown = display_path(str(folder))
            notes.append(f"{shown} is not a usdrender-lint cache folder; left alone")
    return Cleaning(tuple(cleared), tuple(notes), missing)


def _candidates(
    paths: Sequence[str],
    cache_dir: str | os.PathLike[str] | None,
    config: str | None,
    overrides: Sequence[str | Mapping[str, Any]],
    isolated: bool,
    notes: list[str],
) -> Iterator[tuple[Path, bool]]:
    """(folder, whether the user named it) for every cache to look at."""
    if cache_dir:
        yield Path(cache_dir), True
    for path in paths:
        if not cache_dir:
            request = Request(
                paths=(path,), config=config, config_overrides=tuple(overrides), isolated=isolated
            )
            yield cache_folder(resolve_settings(request)), False
        if os.path.isdir(path):
            # Each configuration below has its own cache, unless one for all is given.
            nested = not (cache_dir or config or isolated)
            yield from _below(Path(path), overrides if nested else None, notes)


def _below(
    top: Path, overrides: Sequence[str | Mapping[str, Any]] | None, notes: list[str]
) -> Iterator[tuple[Path, bool]]:
    for folder, subfolders, _ in os.walk(top, onerror=None):
        here = Path(folder)
        if CACHE_DIR_NAME in subfolders:
            subfolders.remove(CACHE_DIR_NAME)  # never walked into
            if not os.path.islink(here / CACHE_DIR_NAME):  # links are not followed
                yield here / CACHE_DIR_NAME, False
        if overrides is None:
            continue
        try:
            found = config_file_in(here)
            if found is not None:
                yield cache_folder(with_inline(read_config_file(found), overrides)), False
        except ConfigError as exc:
            notes.append(f"{exc}; its cache is not looked for")


def _holds_anything(folder: Path) -> bool:
    try:
        with os.scandir(folder) as found:
            return any(True for _ in found)
    except OSError:
        return True


__all__ = ["Cleaning", "clean"]
