"""``check --show-files`` and ``--show-settings``: what a check would lint and
with which settings, without linting (as ruff's options of those names).

The settings are printed as the TOML of a ``.usdrender-lint.toml``: every
configuration key with the value in force and, in a comment, where it came
from (the default, the file, a flag). Read back as a configuration, the text
gives the same settings (``tests/running/test_show.py``).
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from enum import Enum
from typing import Any

from ..config import (
    CONFIG_FILE_NAMES,
    INLINE_PREFIX,
    SELECTION_KEYS,
    Settings,
    reading_once,
    user_config_dir,
)
from ..settings_table import SETTINGS
from .pipeline import (
    Prepared,
    Request,
    collect_targets,
    configuration_parts,
    plan_targets,
    prepare,
)


@reading_once()  # each configuration file read once
def planned_files(request: Request) -> tuple[list[str], list[str]]:
    """The files ``request`` would lint (folders walked, exclusions, each
    file's configuration, roots, its shard) and the run's notes about them.
    Raises RequestError as a run does."""
    prepared = prepare(request)
    notes: list[str] = []
    files = collect_targets(prepared, notes)
    planned: list[str] = []
    for part, found in configuration_parts(prepared, files) or [(prepared, files)]:
        targets, _plan = plan_targets(part, found)
        planned += targets
    # In the order the report lists them (pipeline._joined), not part after part.
    place = {os.path.normpath(file): index for index, file in enumerate(files)}
    planned.sort(key=lambda file: place.get(os.path.normpath(file), len(place)))
    return planned, notes


@reading_once()
def settings_text(request: Request) -> str:
    """The settings ``request`` would lint with, as a configuration file's TOML;
    when some of its files have a nearer configuration, a comment says which
    (``--show-settings`` of one of them shows its settings)."""
    prepared = prepare(request)
    text = settings_toml(prepared)
    parts = configuration_parts(prepared, collect_targets(prepared, []))
    others = [
        (part.settings.source or "none (the defaults)", found)
        for part, found in parts or ()
        if part.settings.source != prepared.settings.source and found
    ]
    if others:
        lines = ["", "# These files have a configuration of their own, not the one above:"]
        for source, found in others:
            lines.append(f"#   {source}: {len(found)} file(s), e.g. {found[0]}")
        text += "\n".join(lines) + "\n"
    return text


def settings_toml(prepared: Prepared) -> str:
    settings = prepared.settings
    source = settings.source or "none (the defaults)"
    if settings.source is None and not prepared.request.isolated:
        source = f"none (the defaults: {_no_user_config()})"
    if settings.user_level:
        source += (
            " (the user's own: no project configuration found; globs relative to the"
            " working directory)"
        )
    codes = sorted(type(rule).code for rule in prepared.linter.rules)
    lines = [
        f"# configuration file: {source}",
        *(f"# which extends: {file}" for file in settings.sources[1:]),
        f"# rules selected: {len(codes)} ({', '.join(codes)})",
    ]
    tables: list[str] = []
    layered = _layered_selection(settings, codes)
    lines += layered
    for entry in SETTINGS:
        if entry.config_key is None or entry.name == "extend":
            continue  # what it extends is folded into the values below
        if layered and entry.name in SELECTION_KEYS:
            continue
        value = getattr(settings, entry.name)
        origin = _origin(settings, entry.name)
        if value is None:  # TOML has no null: the key stays out, as in a file
            meaning = entry.shown_default or entry.help
            lines.append(f"# {entry.config_key} is not set ({origin}): {meaning}")
        elif isinstance(value, Mapping):
            # In the order the globs are tried (a nearer layer's first), so that
            # the printed file chooses the profiles the chain of files does.
            value = dict(settings.nearest_first(entry.name))
            tables.extend(_table(entry.config_key, value, origin))
        else:
            lines.append(f"{entry.config_key} = {_value(value)}  # {origin}")
    return "\n".join(lines + tables) + "\n"


def _no_user_config() -> str:
    """Where the user's own configuration was looked for, as no project one was
    found: a file there of another name (``config.toml``) is not read, silently."""
    folder = user_config_dir()
    if folder is None:
        return "no project configuration found, and no home folder for one of your own"
    said = f"no project configuration found, and none of your own in {folder}"
    try:
        others = sorted(
            p.name
            for p in folder.iterdir()
            if p.suffix == ".toml" and p.name not in CONFIG_FILE_NAMES
        )
    except OSError:  # no such folder: nothing misnamed in it
        return said
    if others:
        *first, last = CONFIG_FILE_NAMES
        are = "is" if len(others) == 1 else "are"
        said += f"; {', '.join(others)} there {are} not read: name it {', '.join(first)} or {last}"
    return said


def _layered_selection(settings: Settings, codes: list[str]) -> list[str]:
    """When the rule selection is laid over another (``selections_below``):
    each layer as a comment, then the rules they choose as one ``select``, so
    that the printed file lints as the layers do."""
    if not settings.selections_below:
        return []
    lines = ["# the rule selection, layer by layer (each starts from what the one before chose):"]
    for layer in settings.selection_layers:
        for key in SELECTION_KEYS:
            value = getattr(layer, key)
            if value is not None and (value or key == "select"):
                config_key = key.replace("_", "-")
                lines.append(f"#   {config_key} = {_value(value)}  ({layer.origins[key]})")
    lines += [
        f"select = {_value(codes)}  # what the layers choose",
        "ignore = []",
        "extend-select = []",
    ]
    return lines


def _origin(settings: Settings, name: str) -> str:
    if name in settings.from_flags:
        return "flag " + "--" + name.replace("_", "-")
    if name in settings.from_file:
        file = settings.from_file[name]
        if file.startswith(INLINE_PREFIX):
            return file  # an inline --config 'KEY = VALUE'
        return "file" if file == settings.source else f"file {file}"
    return "default"


def _table(key: str, value: Mapping[str, Any], origin: str) -> list[str]:
    lines = ["", f"[{key}]  # {origin}"]
    nested = []
    for name, item in value.items():
        if isinstance(item, Mapping):  # rule options: a table per rule
            nested.append(f"\n[{key}.{_key(name)}]")
            nested.extend(f"{_key(k)} = {_value(v)}" for k, v in item.items())
        else:
            lines.append(f"{_key(name)} = {_value(item)}")
    return lines + nested


def _key(name: str) -> str:
    bare = name.replace("-", "").replace("_", "").isalnum() and name.isascii()
    return name if bare else _string(name)


def _string(text: str) -> str:
    # JSON's escapes (\", \\, \n, \uXXXX) are TOML's basic-string escapes too.
    return json.dumps(text, ensure_ascii=False)


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, Enum):
        return _string(str(value.value))
    if isinstance(value, str):
        return _string(value)
    if isinstance(value, int | float):
        return repr(value)
    if isinstance(value, Sequence):
        return "[" + ", ".join(_value(item) for item in value) + "]"
    raise TypeError(f"no TOML form for {value!r}")
