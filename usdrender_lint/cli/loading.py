"""What the commands load before they work: USD and the engine (once, with
the garbage collector paused), the rule registry, and how the supervisor
(running/supervisor.py) ran this process."""

from __future__ import annotations

import gc
import sys
from typing import TYPE_CHECKING

import click

from .output import ToolError

if TYPE_CHECKING:
    from ..registry import Registry
    from ..running.supervisor import Supervision


def registry() -> Registry:
    import_engine()
    from ..registry import RegistryError, build_registry

    try:
        return build_registry()
    except RegistryError as exc:
        raise ToolError(str(exc)) from None


def supervision() -> Supervision | None:
    """What ``main`` was handed by the supervisor (click's context object)."""
    return click.get_current_context().find_root().obj


def import_engine() -> None:
    """Import USD and the engine with the cyclic garbage collector paused, then
    freeze what the imports made. Imports make no garbage worth collecting, and
    each collection on the way would walk every object USD created so far
    (about 10 ms of a one-file check); frozen objects are never walked again.
    Called by the commands that need USD: ``--help`` and ``--version`` do not."""
    if "usdrender_lint.running.pipeline" in sys.modules:
        return
    from ..running.address_space import out_of_memory_at_start, refusal
    from ..running.interrupts import deferred

    # Under too small a ulimit -v, USD's import crashes or prints its own tracebacks.
    if (refused := refusal()) is not None:
        raise ToolError(refused)
    enabled = gc.isenabled()
    gc.disable()
    try:
        with deferred():  # a Ctrl-C arrives after the imports, not inside USD's
            from ..running import pipeline  # noqa: F401 - USD, the engine and the rule API
    except (MemoryError, ImportError) as exc:
        if (said := out_of_memory_at_start(exc)) is None:
            raise
        raise ToolError(said) from None
    finally:
        gc.freeze()
        if enabled:
            gc.enable()
