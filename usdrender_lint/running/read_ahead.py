"""Read a lone file's layers on a second thread while ``check`` or ``spec`` imports the linter.

A one-file ``check`` spends most of its time importing USD, click, the engine
and the rules, and then reads the file. Reading a layer is USD's own work in
C++ and runs without the GIL (``Sdf.Layer.FindOrOpen``; measured here: a
1k-prim ``.usda`` parses in 23 ms beside a busy Python thread, which loses
nothing). So the supervised child (``supervisor.py``), once ``pxr.Sdf`` is
imported, reads the root layer and its sublayers on a thread while it imports
the rest; the lint of that file waits for the read (:func:`held`) and finds
the layers in USD's layer registry, read once. On two CPUs the read is hidden
behind the imports (issue 17, start-up and referenced shots).

Nothing a lint reports can change:

- the thread reads what every lint of the file reads first (the root layer
  stack, as ``Usd.Stage.Open`` and the fast path do), before no spec walk;
- a read that raised or posted any diagnostic keeps no layer, so the lint
  reads the file again and sees USD's errors itself (ST001 quotes them);
- a sublayer path is resolved as the stage resolves it (the default resolver
  context of the root layer, bound on the thread); one it would resolve
  otherwise is read again by the stage, never used in its place;
- the lint waits for the read inside its own time-out, after the memory cap
  (``workers.py``), and a crash while reading is the supervised child's crash,
  reported for the file as any crash of its lint.

Only the supervised child reads ahead, and only a file it lints in its own
process (``cli.py``): not one linted inside the stage roots a configuration
names, whose layers worker processes find, as a read starts USD's thread pool
and a process running threads forks no worker (``workers.py``). The
supervisor's own run after a crash, the Python API and the pool's workers
never read ahead. A read no lint claims (the result cache had the file, or the
configuration excludes it) is left behind: the process ends without waiting
for it (:func:`end_unclaimed`). Before any fork every read ends (:func:`finish`).
"""

from __future__ import annotations

import os
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from typing import Any

from ..layers.crate import crate_structure_problem
from ..paths import usd_path

#: The layer formats read ahead: ``engine.stage.USD_EXTENSIONS`` less a package
#: (``.usdz``), which is left to the lint (the engine is not imported yet).
EXTENSIONS = (".usd", ".usda", ".usdc")
#: Layers of the root layer stack read at most (a deeper stack: the rest is
#: read by the lint, as without a read ahead).
MAX_LAYERS = 64

_pending: dict[str, _Read] = {}
#: The files read ahead, and those whose lint found their layers read, in
#: order (what a test or a profile of the command can ask).
started: list[str] = []
used: list[str] = []
#: When each file's read ahead began (time.time_ns()): what the lint read of it
#: is as old as that (the result cache stores nothing changed since).
_began: dict[str, int] = {}


class _Read:
    """One file's root layer stack, read on a thread."""

    def __init__(self, path: str) -> None:
        self.path = path
        #: The layers read, held until the lint has opened them; empty when the
        #: read failed or posted a diagnostic.
        self.layers: list[Any] = []
        self.thread = threading.Thread(target=self._run, name="usdrender-lint read-ahead")

    def _run(self) -> None:
        from pxr import Tf

        with Tf.DiagnosticTrap() as trap:
            try:
                layers = _root_layer_stack(self.path)
            except Exception:  # noqa: BLE001 - the lint reads the file again and reports it
                layers = []
            if trap.IsClean():
                self.layers = layers
            trap.Clear()


def _root_layer_stack(path: str) -> list[Any]:
    from pxr import Ar, Sdf

    if crate_structure_problem(path) is not None:
        return []  # the lint reports it, without USD reading it
    root = Sdf.Layer.FindOrOpen(usd_path(path))
    if root is None:
        return []
    layers = [root]
    seen = {root.identifier}
    with Ar.ResolverContextBinder(Ar.GetResolver().CreateDefaultContextForAsset(root.identifier)):
        queue = [root]
        while queue and len(layers) < MAX_LAYERS:
            anchor = queue.pop(0)
            for asset_path in anchor.subLayerPaths:
                if "`" in asset_path:
                    continue  # an expression: the stage's variables decide
                file = Sdf.ComputeAssetPathRelativeToLayer(anchor, asset_path)
                if not os.path.isfile(file):
                    continue  # a FIFO would block the read for good: the lint's time-out bounds it
                if crate_structure_problem(file) is not None:
                    continue
                layer = Sdf.Layer.FindOrOpenRelativeToLayer(anchor, asset_path)
                if layer is None or layer.identifier in seen:
                    continue
                seen.add(layer.identifier)
                layers.append(layer)
                queue.append(layer)
    return layers


def wanted(path: str) -> bool:
    """True for a path worth reading ahead: a regular file of a layer format."""
    return path.lower().endswith(EXTENSIONS) and os.path.isfile(path)


def start(path: str) -> None:
    """Start reading ``path``'s root layer stack on a thread. The thread
    imports nothing: ``pxr`` is imported here first."""
    from pxr import Ar, Sdf, Tf  # noqa: F401 - imported on this thread, not the reader's

    read = _Read(path)
    _began.setdefault(_key(path), time.time_ns())
    _pending[_key(path)] = read
    started.append(path)
    read.thread.start()


@contextmanager
def held(path: str) -> Iterator[None]:
    """Around the lint of ``path``: wait for its read ahead (if any) and keep
    the layers it read open until the lint has its own handles."""
    read = _pending.pop(_key(path), None) if _pending else None
    finish()  # a read of another file: not this lint's
    if read is None:
        yield
        return
    read.thread.join()
    if read.layers:
        used.append(path)
    try:
        yield
    finally:
        read.layers.clear()


def began(path: str) -> int | None:
    """When a read ahead of ``path`` began in this process (time.time_ns()), or None."""
    return _began.get(_key(path)) if _began else None


def finish() -> None:
    """Wait for every read ahead and drop its layers (before a fork: a child
    must not inherit a thread inside USD)."""
    while _pending:
        _, read = _pending.popitem()
        read.thread.join()
        read.layers.clear()


def end_unclaimed(code: object) -> None:
    """At the command's end (``code``: its ``SystemExit`` code): when a read
    ahead no lint claimed is still running (the result cache had the file, or
    the configuration excludes it), end the process now, its output flushed,
    rather than wait for USD to finish a read nobody uses. Otherwise return."""
    if not any(read.thread.is_alive() for read in _pending.values()):
        return
    if isinstance(code, str):
        sys.stderr.write(f"{code}\n")
    for stream in (sys.stdout, sys.stderr):
        with suppress(Exception):  # a closed or broken stream: nothing more to say
            stream.flush()
    # os._exit: the interpreter's clean-up would wait for the thread, and USD's
    # own at-exit clean-up must not run beside a read.
    os._exit(code if isinstance(code, int) else 0 if code is None else 1)


def _key(path: str) -> str:
    return os.path.realpath(path)


__all__ = [
    "EXTENSIONS",
    "MAX_LAYERS",
    "began",
    "end_unclaimed",
    "finish",
    "held",
    "start",
    "started",
    "used",
    "wanted",
]
