"""Camera helpers shared by the CA rules: the effective cameras of a stage and
the evaluation of varying camera values at the rendered times (catalog R2-1)."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

from pxr import Usd

from usdrender_lint.api import Context, record, schemas
from usdrender_lint.api.resolve import (
    DEFAULT_TIME,
    PrimValues,
    RenderConfiguration,
    authored_rendered_times,
    fallback_value,
    format_time,
    is_finite,
    prim_values,
    values_in,
)

#: A check over camera values read at one time: a problem phrase, or None.
ValueCheck = Callable[..., str | None]


@record(frozen=True)
class CameraUse:
    """A usable Camera prim and the render configurations it is effective in."""

    prim: Usd.Prim
    configurations: tuple[RenderConfiguration, ...]


def effective_cameras(ctx: Context) -> list[CameraUse]:
    """Each usable Camera that is the effective camera of some configuration,
    once, in first-use order (a camera shared by several products is checked
    once, so it gives one finding)."""
    return ctx.cached(_effective_cameras)


def _effective_cameras(ctx: Context) -> list[CameraUse]:
    # Keyed by the camera's PrimValues (one per prim in a lint, whichever handle
    # asks), which the entry's prim keeps alive: its id is not reused.
    uses: dict[int, tuple[Usd.Prim, list[RenderConfiguration]]] = {}
    for config in ctx.configurations:
        prim = config.camera_prim
        if prim is None:
            continue
        uses.setdefault(id(values_in(ctx.cache, prim)), (prim, []))[1].append(config)
    return [CameraUse(prim, tuple(configs)) for prim, configs in uses.values()]


def config_owners(config: RenderConfiguration) -> list[Usd.Prim]:
    """The prims whose RenderSettingsBase opinions make up a configuration
    (only the product for a product rendered on its own)."""
    if config.settings is None or config.product is None:
        return [config.owner]
    return [config.settings, config.product]


def config_authors(config: RenderConfiguration, name: str) -> bool:
    """Whether a prim of :func:`config_owners` holds an authored value of ``name``
    (asked without building the list: once per configuration and rule)."""
    settings, product = config.settings, config.product
    return (settings is not None and prim_values(settings).has_value(name)) or (
        product is not None and prim_values(product).has_value(name)
    )


def first_failure(
    prim: Usd.Prim, names: Iterable[str], check: ValueCheck, ctx: Context
) -> tuple[Usd.TimeCode, str] | None:
    """Evaluate ``check(*values)`` at the rendered times of the named
    attributes (catalog R2-1: Default when none has time samples, else their
    sample times within the stage's time range; see
    :func:`~usdrender_lint.api.resolve.rendered_times`); the first failing
    time and its problem.

    Values are composed: well-typed authored opinions, else the schema
    fallback (a type-mismatched opinion counts as unauthored, SE016's; a
    blocked sample reads as the fallback)."""
    names = tuple(names)
    values = prim_values(prim)
    # An attribute that provably has no time samples adds no rendered time (on a
    # stage where nothing varies, none: nothing to ask per name).
    sampled = (
        None
        if ctx.cache.nothing_varies
        else [
            values.attribute(name)
            for name in names
            if values.has_value(name) and values.may_vary(name)
        ]
    )
    if not sampled:
        # Default is the only rendered time: the check reads the values PrimValues
        # holds for the lint (every CA rule shares them), not a read per check.
        # What _value_at reads at Default: the composed value (the authored one
        # is Get()'s at Default), else the fallback (no helper call per name).
        composed = values.composed
        problem = check(
            *[v if (v := composed(name)) is not None else values.fallback(name) for name in names]
        )
        return None if problem is None else (DEFAULT_TIME, problem)
    readers = [_reader(values, name) for name in names]
    for time in authored_rendered_times(sampled, ctx.time_sample_cap):
        problem = check(*(_value_at(reader, time) for reader in readers))
        if problem is not None:
            return time, problem
    return None


#: The attribute when it holds a well-typed authored value (else None: no
#: handle is needed), and its fallback (read when first needed for an authored
#: one: only a blocked sample needs it).
_Reader = tuple[Usd.Attribute | None, Any]
_NOT_READ: Any = object()


def _reader(values: PrimValues, name: str) -> _Reader:
    # Decided once per attribute and lint (PrimValues), not per time sample or
    # rule: the opinion stack is costly and several CA rules read the same attributes.
    if values.has_value(name):
        return values.attribute(name), _NOT_READ
    return None, values.fallback(name)


def _value_at(reader: _Reader, time: Usd.TimeCode) -> Any:
    attr, fallback = reader
    if attr is None:
        return fallback
    value = Usd.Attribute.Get(attr, time)  # unbound: attr holds a value (_reader)
    if value is not None:
        return value
    # A blocked time sample (`1: None`) leaves typed C++ reads with the fallback.
    return fallback_value(attr.GetPrim(), attr.GetName()) if fallback is _NOT_READ else fallback


def at_time(time: Usd.TimeCode) -> str:
    return f"at {format_time(time)}"


def is_perspective(projection: Any) -> bool:
    return str(projection) == "perspective"


def positive_finite(value: Any) -> bool:
    return value is not None and is_finite(value) and value > 0


def usable_cameras(ctx: Context, most: int = 2) -> list[Usd.Prim]:
    """The first ``most`` usable Cameras on the stage (enough to tell "exactly
    one"). Walks the stage: only call it for a fix that needs it."""
    # Cameras anywhere in the scene: not on the engine's partial stage.
    ctx.require_full_stage()
    return ctx.cached(_usable_cameras, most)


def _usable_cameras(ctx: Context, most: int) -> list[Usd.Prim]:
    cameras: list[Usd.Prim] = []
    is_camera_type: dict[str, bool] = {}
    for prim in ctx.stage.Traverse():
        type_name = prim.GetTypeName()
        hit = is_camera_type.get(type_name)
        if hit is None:  # IsA depends on the type name only: test it once per type
            hit = is_camera_type[type_name] = prim.IsA(schemas.Camera)
        if hit:
            cameras.append(prim)
            if len(cameras) == most:
                break
    return cameras
