"""A worker's next file, read by USD while the worker lints the one before.

A worker holds its next item in its pipe while it lints one (workers.IN_FLIGHT).
With a core to spare (``--jobs 1`` on 2 cores) that core idles while the rules,
which are Python on one thread, run. USD parses a layer without holding
Python's interpreter lock, so a thread that receives each item and has USD open
its root layer (``Sdf.Layer.FindOrOpen``, which the lint's own open then finds
in USD's layer registry) takes the parse of the next file off the critical path
(benchmarks/run.py --only gate; docs/guides/performance.md).

It changes no answer:

- a file is read here only once it passes the checks the engine makes before
  USD reads any file (``unsafe_to_open``: a corrupt crate, a text layer nested
  deep enough to overflow USD's parser), so what makes USD crash or hang
  is found in the file's own lint, as without this;
- a file linted again after its worker died (``FullyComposed``) is not read
  ahead, nor is the item after it: should a read ahead crash USD in a way no
  check knows, the item the worker was linting is linted again alone and the
  crash then falls on the file that caused it;
- the layer is used only when the file is unchanged (size, modification and
  change times, inode) when its lint starts, and was not changed within a
  clock tick of its stamp (a rewrite then may keep every field); else it is
  dropped and USD reads the file again.
"""

from __future__ import annotations

import os
import queue
import stat
import threading
from collections.abc import Callable
from contextlib import suppress
from typing import TYPE_CHECKING, Any

from ..config import FileState, stat_state

if TYPE_CHECKING:
    from multiprocessing.connection import Connection

#: What the reader puts in the inbox when the parent is gone.
_GONE = object()
#: Root layer formats read ahead (a package's layers are read through its resolver).
_READ_AHEAD = (".usda", ".usdc", ".usd")


def spare_core(workers: int) -> bool:
    """Whether ``workers`` workers leave a core idle while each runs its rules."""
    return workers < (os.cpu_count() or 1)


class Reader:
    """Receives a worker's items in a thread of its own, each root layer opened
    as it arrives; :meth:`next` gives them in order."""

    def __init__(self, conn: Connection, is_retry: Callable[[Any], bool]) -> None:
        """``is_retry(item)``: the item is a file linted again after a crash."""
        self._conn = conn
        self._is_retry = is_retry
        self._inbox: queue.Queue[Any] = queue.Queue()
        thread = threading.Thread(target=self._receive, name="read-ahead", daemon=True)
        thread.start()

    def next(self) -> tuple[int, Any, Any]:
        """The next ``(index, item)`` and the layer read for it (None: none, or
        the file changed since); raises EOFError once the parent is gone."""
        entry = self._inbox.get()
        if entry is _GONE:
            raise EOFError
        index, item, layer, stamp = entry
        if layer is not None and _stamp(item) != stamp:
            layer = None  # changed since it was read: the lint reads it again
        return index, item, layer

    def _receive(self) -> None:
        after_retry = False
        while True:
            try:
                index, item = self._conn.recv()
            except (EOFError, OSError):
                self._inbox.put(_GONE)
                return
            layer, stamp = None, None
            retry = self._is_retry(item)
            if not (retry or after_retry):
                stamp = _stamp(item)
                layer = _read(item) if stamp is not None else None
            after_retry = retry
            self._inbox.put((index, item, layer, stamp))


def _stamp(path: Any) -> FileState:
    if not isinstance(path, str) or not path.lower().endswith(_READ_AHEAD):
        return None
    try:
        info = os.stat(path)
    except OSError:
        return None
    if not stat.S_ISREG(info.st_mode):
        return None  # a FIFO, a device: read only by its own lint, which may wait on it
    # The change time too (a rewrite that kept its modification time), and a
    # file changed as it was stamped never matches (config.stat_state).
    return stat_state(info)


def _read(path: str) -> Any:
    """``path``'s root layer opened by USD, or None (not safe to read here, or
    USD could not: the file's lint says why)."""
    from pxr import Sdf, Tf

    from ..engine.linter import unsafe_to_open
    from ..paths import usd_path

    with suppress(Exception):
        if unsafe_to_open(path) is None:
            with Tf.DiagnosticTrap() as trap:
                try:
                    return Sdf.Layer.FindOrOpen(usd_path(path))
                finally:
                    trap.Clear()  # its lint reports what USD says of it
    return None


__all__ = ["Reader", "spare_core"]
