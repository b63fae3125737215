"""Where a diagnostic is: the layer of the strongest opinion behind it and,
in a text ``.usda``, the line of that opinion."""

from __future__ import annotations

import os

from pxr import Sdf, Usd

from ..api.text import MAX_MESSAGE_CHARS
from ..layers.files import real_path
from ..model import Location
from . import layer_words


def bounded_message(message: str) -> str:
    """At most MAX_MESSAGE_CHARS of a message: a rule quoting a ten-million-element
    array must not put hundreds of megabytes into every report."""
    if len(message) <= MAX_MESSAGE_CHARS:
        return message
    return f"{message[:MAX_MESSAGE_CHARS]}… ({len(message) - MAX_MESSAGE_CHARS} more characters)"


def _spec_stack(obj: Usd.Object) -> list[Sdf.Spec]:
    if isinstance(obj, Usd.Attribute):
        clip = _clip_spec(obj)
        if clip is not None:
            return [clip]
    if isinstance(obj, Usd.Property):
        return list(obj.GetPropertyStack(Usd.TimeCode.Default()))
    if isinstance(obj, Usd.Prim):
        return list(obj.GetPrimStack())
    return []


def _clip_spec(attribute: Usd.Attribute) -> Sdf.Spec | None:
    """The spec in a value clip that holds the attribute's value, when its value
    comes from value clips: the property stack at the default time leaves clip
    layers out (UsdProperty::GetPropertyStack, pxr/usd/usd/property.h), so a
    value only a clip holds had no layer. The clip active at the first sample."""
    if attribute.GetResolveInfo().GetSource() != Usd.ResolveInfoSourceValueClips:
        return None
    bracket = attribute.GetBracketingTimeSamples(-float("inf"))  # () when it has none
    if not bracket:
        return None
    for spec in attribute.GetPropertyStack(Usd.TimeCode(bracket[0])):
        if spec.layer.GetNumTimeSamplesForPath(spec.path):
            return spec
    return None


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
    spec, chosen = _strongest_spec(at, layer)
    line = _line_of(spec, chosen) if spec is not None and chosen is not None else None
    return Location(file, str(at.GetPath()), real_path(chosen) if chosen else None, line)


def _strongest_spec(
    at: Usd.Object, layer: Sdf.Layer | None
) -> tuple[Sdf.Spec | None, Sdf.Layer | None]:
    """The strongest spec behind ``at`` (in ``layer`` when it has one there) and
    the layer a finding names: ``layer`` when given, else that spec's."""
    specs = _spec_stack(at)
    if layer is not None:
        specs = [s for s in specs if s.layer == layer] or specs
        return next(iter(specs), None), layer
    spec = next(iter(specs), None)
    return spec, spec.layer if spec is not None else None


def _line_of(spec: Sdf.Spec, layer: Sdf.Layer) -> int | None:
    """The line that opens ``spec`` in ``layer``'s text, when it is a text file."""
    if not _is_text_file(layer):
        return None
    from ..layers import usda_text  # its regular expressions cost start-up: only findings need it

    return usda_text.line_of(real_path(layer), str(spec.path))


def _is_text_file(layer: Sdf.Layer) -> bool:
    # A layer with unsaved edits may have no file yet: its lint may hold its text
    # (usda_text.hold_text); otherwise no line is found.
    path = real_path(layer)
    if not path:
        return False
    format_id = layer.GetFileFormat().formatId
    if format_id == "usd":  # .usd is text or a crate: its first bytes say which
        return os.path.isfile(path) and layer_words.is_text_file(path)
    return format_id == "usda" and (layer.dirty or os.path.isfile(path))
