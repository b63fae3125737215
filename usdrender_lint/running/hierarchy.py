"""Which configuration each file is linted with: the nearest one above it, as
ruff reads a project's configurations and as the language server lints each
document. A check of ``shows/`` whose shows each keep a ``.usdrender-lint.toml``
lints every show's shots with that show's settings.

A run whose files all have the configuration found from its first path (nearly
every run) is one run, as before. Otherwise the pipeline splits it into a part
per configuration: one set of workers lints every part's files, each with its
part's linter, and the parts' outcomes are joined. Only a check that searches
for its configuration is split: ``--config`` and ``--isolated`` give every file
one configuration, and a text on standard input is one file.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from ..config import config_file_in, search_start
from ..records import record


@record(frozen=True)
class Group:
    """Files that share a configuration file (None: none, the defaults)."""

    config: str | None
    files: tuple[str, ...]


class _Nearest:
    """The nearest configuration file of each folder, each folder asked once
    (a tree of shots shares a handful of configurations)."""

    def __init__(self) -> None:
        self._of: dict[Path, str | None] = {}
        #: By the folder as named: the files of one folder resolve it once.
        self._named: dict[str, str | None] = {}

    def of_file(self, file: str) -> str | None:
        named = os.path.dirname(file)
        linked = os.path.islink(file)  # its target's folder, not its own
        if named in self._named and not linked:
            return self._named[named]
        nearest = self._of_folder(search_start(file))
        if not linked and not os.path.isdir(file):
            self._named[named] = nearest
        return nearest

    def _of_folder(self, folder: Path) -> str | None:
        below: list[Path] = []
        while folder not in self._of:
            found = config_file_in(folder)
            if found is not None:
                self._of[folder] = str(found)
                break
            below.append(folder)
            if folder.parent == folder:
                self._of[folder] = None
                break
            folder = folder.parent
        nearest = self._of[folder]
        for each in below:
            self._of[each] = nearest
        return nearest


def configuration_groups(files: Sequence[str], found: str | None) -> list[Group] | None:
    """``files`` by their nearest configuration, in the order they come; None
    when every one has ``found``, the configuration of the run's first path.
    Raises ConfigError for a configuration file that cannot be read."""
    nearest = _Nearest()
    by_config: dict[str | None, list[str]] = {}
    for file in files:
        by_config.setdefault(nearest.of_file(file), []).append(file)
    if set(by_config) <= {found}:
        return None
    return [Group(config, tuple(group)) for config, group in by_config.items()]


def given_files(paths: Sequence[str]) -> set[str]:
    """The paths given that are not folders: linted whatever a walk would skip."""
    return {os.path.normpath(path) for path in paths if not os.path.isdir(path)}
