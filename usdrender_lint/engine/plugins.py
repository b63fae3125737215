"""USD's plugin registration, forced once per process, early, its errors trapped.

USD registers the plugins on ``PXR_PLUGINPATH_NAME`` lazily, at whatever call of
the process first needs them, and posts a plugin's registration problems (a
``plugInfo.json`` it cannot read, a schema type whose alias clashes) as Tf errors
there: usd-core's bindings raise them from that call, which may be a file's
``Usd.Stage.Open`` (its ST001), a worker starting, or a cache lookup. They are
the environment's problems, not a file's, and the same in every process.

So :func:`register_plugins` comes before the tool's first USD call in each
process that uses USD: a lint's opening of its file (the engine), a pool
worker's start, a cache lookup, a roots plan, the language server's documents.
Not when a linter is built: registration starts USD's threads, and the process
that builds one may yet fork its workers, which it does only while it has one
thread (running/workers.py; a forkserver instead took two files from 0.33 s to
0.6 s). The run says the problems once (:func:`plugin_notes`): its own, or
those its workers reported (:func:`reported_by_worker`) when it only handed
files out. Files are linted with the registry as USD left it.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable

from pxr import Plug, Tf, Usd

from ..api import schemas

#: The calls that make USD register every plugin (found by experiment, usd-core
#: 26.11): reading the plugins declares their types (a clashing alias fails
#: here), and the schema registry then maps every schema type (a schema that
#: failed to register is reported here).
_REGISTERING: tuple[Callable[[], object], ...] = (
    lambda: Plug.Registry().GetAllPlugins(),
    Usd.SchemaRegistry,
)

#: The schemas whose prim definitions (their attributes' fallback values) the
#: rules read: UsdRender's and UsdGeom's camera.
_DEFINED = (
    schemas.RenderSettings,
    schemas.RenderProduct,
    schemas.RenderVar,
    schemas.RenderPass,
    schemas.Camera,
)
#: USD's own switch that builds the schema registry without prim definitions
#: (``pxr/usd/usd/schemaRegistry.cpp``, for usdGenSchema only), and the values
#: that turn a boolean setting on (``TfGetenvBool``, ``pxr/base/tf/getenv.cpp``).
_NO_DEFINITIONS_SETTING = "USD_DISABLE_PRIM_DEFINITIONS_FOR_USDGENSCHEMA"
_ON = ("1", "true", "yes", "on")

_problems: tuple[str, ...] | None = None
#: The schemas of ``_DEFINED`` without a prim definition in this process.
_missing: tuple[str, ...] = ()
#: The problems worker processes of this one reported, in order.
_heard: dict[str, None] = {}


class SchemasMissing(Exception):
    """USD's schema registry has no prim definition for a schema the rules read:
    every fallback value would be None and the findings wrong, so nothing is linted.
    USD builds a definition from its plugin's ``generatedSchema.usda`` and, when it
    cannot open that layer (out of memory under ``ulimit -v``), warns and goes on
    with an empty one (``_GetGeneratedSchema``, ``pxr/usd/usd/schemaRegistry.cpp``)."""

    def __init__(self, types: tuple[str, ...]) -> None:
        self.types = types
        #: Whether USD was told to build no definitions (else it could not read them).
        self.disabled = os.environ.get(_NO_DEFINITIONS_SETTING, "").lower() in _ON
        why = "USD could not read their schemas"
        if self.disabled:
            why = f"{_NO_DEFINITIONS_SETTING} is set, for usdGenSchema only: unset it"
        super().__init__(
            f"USD's schema registry has no prim definition for {', '.join(types)} ({why}); "
            "the rules would read no fallback values, so nothing was linted"
        )


def register_plugins() -> tuple[str, ...]:
    """Have USD register its plugins now, once per process; the problems it
    reported (one line each, in order, no repeats), every time it is asked.
    Raises :class:`SchemasMissing`, every time, when the schemas the rules
    read have no prim definitions."""
    global _problems, _missing
    if _problems is None:
        found: list[str] = []
        for call in _REGISTERING:
            with Tf.DiagnosticTrap() as trap:
                try:
                    call()
                except Tf.ErrorException as exc:
                    found += [str(getattr(arg, "commentary", arg)) for arg in exc.args]
                found += [d.commentary for d in (*trap.GetErrors(), *trap.GetWarnings())]
                trap.Clear()
        lines = (line.strip() for text in found for line in text.splitlines())
        _problems = tuple(dict.fromkeys(line for line in lines if line))
        _missing = _undefined()
    if _missing:
        raise SchemasMissing(_missing)
    return _problems


def _undefined() -> tuple[str, ...]:
    registry = Usd.SchemaRegistry()
    names = [Usd.SchemaRegistry.GetSchemaTypeName(schema) for schema in _DEFINED]
    return tuple(name for name in names if registry.FindConcretePrimDefinition(name) is None)


def reported_by_worker(problems: Iterable[str]) -> None:
    """Keep the problems a worker's :func:`register_plugins` reported."""
    _heard.update(dict.fromkeys(problems))


def plugin_problems() -> tuple[str, ...]:
    """The problems of this process's registration and its workers', without
    registering (that costs a process that only handed files out 20 ms)."""
    return tuple(dict.fromkeys((*(_problems or ()), *_heard)))


def plugin_notes() -> list[str]:
    """The run's notes on the plugin registration problems (stderr's lines)."""
    return [f"warning: USD plugin registration: {problem}" for problem in plugin_problems()]
