"""What the commands load before they work: USD and the engine (once, with
the garbage collector paused), the rule registry, and how the supervisor
(running/supervisor.py) ran this process."""

from __future__ import annotations

import gc
import sys
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from importlib import import_module
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
    """Import USD, the engine and the built-in rules with the cyclic garbage
    collector paused, then freeze what the imports made (collection_paused):
    each collection on the way would walk every object USD created so far
    (about 10 ms of a one-file check). Called by the commands that need USD:
    ``--help`` and ``--version`` do not."""
    if "usdrender_lint.running.pipeline" in sys.modules:
        return
    from ..running.address_space import out_of_memory_at_start, refusal
    from ..running.interrupts import deferred

    # Under too small a ulimit -v, USD's import crashes or prints its own tracebacks.
    if (refused := refusal()) is not None:
        raise ToolError(refused)
    try:
        with collection_paused(), deferred():  # a Ctrl-C arrives after the imports
            from ..running import pipeline  # noqa: F401 - USD, the engine and the rule API

            _import_builtin_rules()
    except (MemoryError, ImportError) as exc:
        if (said := out_of_memory_at_start(exc)) is None:
            raise
        raise ToolError(said) from None
    from ..running.collector import collect_less_often

    collect_less_often()  # this process lints next (and its forked workers)


def _import_builtin_rules() -> None:
    """The built-in rule modules, which every command that imports the engine
    registers next: imported here, under the same pause. Their entry point
    still loads them (build_registry), and says why if they fail to import."""
    with suppress(Exception):  # build_registry imports them again, and says why
        import_module("usdrender_lint.rules")


@contextmanager
def collection_paused() -> Iterator[None]:
    """Imports inside: the cyclic garbage collector paused, then what they made
    frozen. Imports make no garbage worth collecting, and each collection on
    the way walks every young object made so far; frozen objects (modules,
    classes, functions: kept to the end anyway) are never walked again."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if enabled:
            gc.enable()
