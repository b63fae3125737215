"""``check --watch``: wait for a change that can change the report.

The paths given are watched (recursively) through the operating system's file
events (``watchfiles``, the ``[watch]`` extra): a layer the walk would lint, a
configuration file (``.toml``) or a ``.gitignore`` changing, appearing or going.
The configuration files in effect and the baseline may lie outside those paths
(a show's ``pyproject.toml`` above the shots): their stamps are compared once a
second instead, since an editor's save replaces a file, which a watch on the
file itself would lose; so are those of the files given. Events that come while
a round lints are kept for the next wait, so no save is missed.
"""

from __future__ import annotations

import os
import stat
import time
from collections.abc import Iterable, Iterator, Sequence
from typing import Any

from ..config import FileState, file_state
from ..engine import USD_EXTENSIONS
from .interrupts import check_stopped

#: The one-line error when the extra is missing.
MISSING = "--watch needs the watchfiles package (the [watch] extra): pip install watchfiles"
#: Seconds between looks at the polled files.
POLL_SECONDS = 1.0
#: Milliseconds the file events are waited for at a time: the watch starts (and
#: the first round waits) that long, and a signal is heard within it.
EVENT_WAIT_MS = 100
#: What else, besides layers, changes a report.
CONFIG_SUFFIX = ".toml"
GITIGNORE = ".gitignore"


class WatchUnavailable(Exception):
    """The ``[watch]`` extra is not installed, or no path given exists."""


def relevant(path: str, root: str) -> bool:
    """Whether a change to ``path`` (below the watched ``root``) can change a
    report: a layer, a configuration file, a ``.gitignore`` or a folder moved in,
    outside the hidden folders the walk skips (``.git``, the result cache's)."""
    inside = os.path.relpath(path, root).split(os.sep) if path != root else []
    if any(part.startswith(".") for part in inside[:-1]):
        return False
    name = os.path.basename(path)
    if os.path.isdir(path):
        return not name.startswith(".")
    return (
        name.lower().endswith(USD_EXTENSIONS) or name.endswith(CONFIG_SUFFIX) or name == GITIGNORE
    )


def _identity(path: str) -> tuple[int, int] | None:
    """Which folder is at ``path``, (-1, -1) for a file, None for nothing: a
    folder removed and made again is another one (a file saved again is the
    same: its stamp is polled)."""
    try:
        status = os.stat(path)
    except OSError:
        return None
    if not stat.S_ISDIR(status.st_mode):
        return (-1, -1)
    return (status.st_dev, status.st_ino)


class Watcher:
    """Waits, round after round, for a relevant change below ``paths`` or to one
    of the polled ``files``. Created once: what changes during a round is seen
    by the next :meth:`wait`."""

    def __init__(self, paths: Sequence[str]) -> None:
        try:
            import watchfiles
        except ImportError as exc:
            raise WatchUnavailable(MISSING) from exc
        self._watch = watchfiles.watch
        given = list(dict.fromkeys(os.path.abspath(p) for p in paths))
        if not any(os.path.exists(p) for p in given):
            missing = ", ".join(paths)
            raise WatchUnavailable(f"--watch: nothing to watch: {missing}: no such file or folder")
        # The paths given are polled for coming and going too: the operating
        # system's watch on a folder ends when it is removed (a folder saved
        # again in its place went unseen), and a path given that does not exist
        # yet has no watch until it appears. Either way the events start again
        # over the paths that exist then.
        self._given: dict[str, tuple[int, int] | None] = {p: _identity(p) for p in given}
        self.paths = [p for p, identity in self._given.items() if identity is not None]
        # A file given is polled too: an editor's save replaces it, which ends
        # the operating system's watch on the file (the next save went unseen).
        # Its state is more than its modification time: a file rewritten with
        # that time kept (config.file_state) is a change too. The operating
        # system's events tell a rewrite in place: a stamp taken as the file
        # changed is kept as it is (else the next poll re-ran the check).
        self._polled: dict[str, FileState] = {f: _state(f) for f in self._files()}
        self._events: Iterator[set[Any]] | None = None
        self._start_events()

    def _start_events(self) -> set[str]:
        """Watch the paths that exist now; what was heard since they were read."""
        if self._events is not None:
            close = getattr(self._events, "close", None)
            if close is not None:
                close()  # ends the old watch
            self._events = None
        if not self.paths:
            return set()
        self._events = self._watch(
            *self.paths,
            watch_filter=lambda _change, path: relevant(path, self._root_of(path)),
            rust_timeout=EVENT_WAIT_MS,
            yield_on_timeout=True,
            # A signal raises the command's own Stopped (running/interrupts.py).
            raise_interrupt=True,
        )
        # The generator starts watching at its first step: take it now, so that a
        # save during the first round is seen (what it yields came before).
        try:
            return self._next_events()
        except OSError:
            # A path went again between the look and the start: the next look
            # at the paths given sees it.
            self._events = None
            return set()

    def _files(self) -> set[str]:
        """The paths given that are files now."""
        return {p for p in self._given if os.path.isfile(p)}

    def _root_of(self, path: str) -> str:
        """The watched path ``path`` is below (the longest, when they nest)."""
        below = [p for p in self.paths if path == p or path.startswith(p.rstrip(os.sep) + os.sep)]
        return max(below, key=len, default=os.path.dirname(path))

    def poll(self, files: Iterable[str]) -> None:
        """Also watch ``files`` (outside the paths, say), from their state now."""
        wanted = {os.path.abspath(f) for f in files} | self._files()
        self._polled = {f: self._polled.get(f, _state(f)) for f in wanted}

    def wait(self) -> list[str]:
        """Block until something relevant changed; the paths that did, sorted."""
        changed: set[str] = set()
        polled_at = time.monotonic()
        while not changed:
            changed = self._next_events()
            if time.monotonic() - polled_at >= POLL_SECONDS or changed:
                polled_at = time.monotonic()
                changed |= self._polled_changes() | self._given_changes()
        return sorted(changed)

    def _next_events(self) -> set[str]:
        if self._events is None:
            time.sleep(EVENT_WAIT_MS / 1000)  # nothing to hear: wait as a watch would
            return set()
        try:
            return {path for _change, path in next(self._events)}
        except KeyboardInterrupt:
            # watchfiles turns any signal into KeyboardInterrupt: the command's own
            # Stopped says which (exit 130 or 143).
            check_stopped()
            raise

    def _given_changes(self) -> set[str]:
        """The paths given that appeared, went or were made again since the
        last look; the events start again over the paths that exist now."""
        changed = set()
        for path, identity in self._given.items():
            now = _identity(path)
            if now != identity:
                self._given[path] = now
                changed.add(path)
        if changed:
            self.paths = [p for p, identity in self._given.items() if identity is not None]
            changed |= self._start_events()
        return changed

    def _polled_changes(self) -> set[str]:
        changed = set()
        for path, stamp in self._polled.items():
            now = _state(path)
            if now != stamp:
                self._polled[path] = now
                changed.add(path)
        return changed


def _state(path: str) -> FileState:
    return file_state(path, racy=False)


__all__ = ["MISSING", "WatchUnavailable", "Watcher", "relevant"]
