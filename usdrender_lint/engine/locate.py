"""Where a diagnostic is: the layer of the strongest opinion behind it and,
in a text ``.usda``, the line of that opinion."""

from __future__ import annotations

import os

from pxr import Sdf, Usd

from ..api.text import MAX_MESSAGE_CHARS
from ..layers.files import real_path
from ..model import Location


def bounded_message(message: str) -> str:
    """At most MAX_MESSAGE_CHARS of a message: a rule quoting a ten-million-element
    array must not put hundreds of megabytes into every report."""
    if len(message) <= MAX_MESSAGE_CHARS:
        return message
    return f"{message[:MAX_MESSAGE_CHARS]}… ({len(message) - MAX_MESSAGE_CHARS} more characters)"


def _spec_stack(obj: Usd.Object) -> list[Sdf.Spec]:
    if isinstance(obj, Usd.Property):
        return list(obj.GetPropertyStack(Usd.TimeCode.Default()))
    if isinstance(obj, Usd.Prim):
        return list(obj.GetPrimStack())
    return []


def locate(
    stage: Usd.Stage,
    file: str,
    at: Usd.Object | Sdf.Path | None,
    layer: Sdf.Layer | None = None,
) -> Location:
    """Where a diagnostic is: its path, the layer of the strongest opinion
    behind it (or ``layer`` when given), and the line there in a ``.usda``."""
    if isinstance(at, Sdf.Path):
        at = stage.GetObjectAtPath(at) or at
    if at is None:
        root = layer or stage.GetRootLayer()
        return Location(file, None, real_path(root), None)
    if isinstance(at, Sdf.Path):
        return Location(file, str(at), real_path(layer) if layer else None, None)
    specs = _spec_stack(at)
    if layer is not None:
        specs = [s for s in specs if s.layer == layer] or specs
        spec = next(iter(specs), None)
        chosen = layer
    else:
        spec = next(iter(specs), None)
        chosen = spec.layer if spec is not None else None
    line = None
    if spec is not None and chosen is not None and _is_text_file(chosen):
        from ..layers import (
            usda_text,  # its regular expressions cost start-up: only findings need it
        )

        line = usda_text.line_of(real_path(chosen), str(spec.path))
    return Location(file, str(at.GetPath()), real_path(chosen) if chosen else None, line)


def _is_text_file(layer: Sdf.Layer) -> bool:
    # A layer with unsaved edits may have no file yet: its lint may hold its text
    # (usda_text.hold_text); otherwise no line is found.
    path = real_path(layer)
    return (
        bool(path)
        and layer.GetFileFormat().formatId == "usda"
        and (layer.dirty or os.path.isfile(path))
    )
