"""What the commands load before they work: USD and the engine (once, with
the garbage collector paused), and the rule registry."""

from __future__ import annotations

import gc
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING

from ..config import ConfigError, load_settings
from ..running import read_ahead as _read_ahead
from ..running import supervisor
from ..running.workers import limit_supervised_memory
from .output import ToolError

if TYPE_CHECKING:
    from ..registry import Registry


def registry() -> Registry:
    import_engine()
    from ..registry import RegistryError, build_registry

    try:
        return build_registry()
    except RegistryError as exc:
        raise ToolError(str(exc)) from None


def linted_here(
    paths: Sequence[str], config_path: str | None, isolated: bool, no_roots: bool
) -> str | None:
    """The file the supervised child will lint in its own process, if any: a
    lone layer file not linted inside the stage roots a configuration names
    (the roots' layers are found in worker processes)."""
    if not supervisor.supervised or len(paths) != 1 or not _read_ahead.wanted(paths[0]):
        return None
    if not no_roots:
        try:
            roots = load_settings(config_path, isolated=isolated, start=paths[0]).roots
        except (ConfigError, OSError):
            return None  # the run says what is wrong
        if roots:
            return None
    return paths[0]


def import_engine(read_ahead: str | None = None) -> None:
    """Import USD and the engine with the cyclic garbage collector paused, then
    freeze what the imports made. Imports make no garbage worth collecting, and
    each collection on the way would walk every object USD created so far
    (about 10 ms of a one-file check); frozen objects are never walked again.
    Called by the commands that need USD: ``--help`` and ``--version`` do not.
    ``read_ahead``: a file whose layers are read on a thread meanwhile, under
    the supervised child's memory cap (running/read_ahead.py)."""
    if "usdrender_lint.running.pipeline" in sys.modules:
        return
    from ..running.interrupts import deferred

    enabled = gc.isenabled()
    gc.disable()
    try:
        with deferred():  # a Ctrl-C arrives after the imports, not inside USD's
            if read_ahead is not None:
                limit_supervised_memory()
                _read_ahead.start(read_ahead)
            from ..running import pipeline  # noqa: F401 - USD, the engine and the rule API
    finally:
        gc.freeze()
        if enabled:
            gc.enable()
