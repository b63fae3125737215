"""``usdrender-lint config [KEY]``: the configuration keys and what each takes, as
``ruff config`` lists its settings. Read from the settings table and the JSON
Schema made from it (config.json_schema), so it cannot disagree with the parser."""

from __future__ import annotations

from typing import Any, TextIO

import click

from .output import ToolError
from .views import emit, format_option, view

#: What an unset key means, where "none" would not say it.
_UNSET = {"select": "every rule"}
#: How a file that ``extend``s another combines a key's value with that file's.
_EXTENDED = {
    "replaced": "replaces the extended file's value",
    "merged": "merges with the extended file's table, entry by entry",
    "added": "adds to the extended file's list",
}


def _described(key: str, schema: dict[str, Any]) -> dict[str, Any]:
    import json  # not at start-up: only this command needs it

    from ..settings_table import BY_CONFIG_KEY

    entry = BY_CONFIG_KEY[key]
    default = entry.shown_default or _UNSET.get(key)
    if default is None:
        default = "none" if entry.default in (None, (), {}) else json.dumps(_plain(entry.default))
    return {
        "key": key,
        "description": schema.get("description", entry.help),
        "type": _type_words(schema),
        "default": default,
        "flag": entry.flag,
        "extend": _EXTENDED[entry.extended],
    }


def _plain(value: Any) -> Any:
    return list(value) if isinstance(value, tuple) else value


def _type_words(schema: dict[str, Any]) -> str:
    """A JSON Schema's value in words: "a list of strings, or a string"."""
    import json

    if "anyOf" in schema:
        return ", or ".join(_type_words(part) for part in schema["anyOf"])
    if "enum" in schema:
        return "one of " + ", ".join(json.dumps(value) for value in schema["enum"])
    kind = schema.get("type")
    if kind == "array":
        return f"a list of {_type_words(schema.get('items', {})).removeprefix('a ')}s"
    if kind == "object":
        values = list(schema.get("patternProperties", {}).values())
        if len(values) == 1:  # per-path-ignores, per-path-profiles
            return f"a table of file globs, each to {_type_words(values[0])}"
        return "a table"
    if kind == "integer" and "minimum" in schema:
        return f"an integer of at least {schema['minimum']}"
    words = {"string": "a string", "integer": "an integer", "number": "a number"}
    words["boolean"] = "a boolean"
    return words.get(str(kind), "a value")


@view("config", "text")
def _text(described: list[dict[str, Any]] | dict[str, Any], stream: TextIO) -> None:
    if isinstance(described, list):
        width = max(len(d["key"]) for d in described)
        for d in described:
            stream.write(f"{d['key']:<{width}}  {d['description']}\n")
        return
    stream.write(f"{described['key']}: {described['description']}\n\n")
    stream.write(f"Type: {described['type']}\nDefault: {described['default']}\n")
    if described["flag"]:
        stream.write(f"Flag: {described['flag']}\n")
    stream.write(f"In a file that extends another, it {described['extend']}.\n")


@view("config", "json")
def _json(described: list[dict[str, Any]] | dict[str, Any], stream: TextIO) -> None:
    import json

    stream.write(json.dumps(described, indent=2) + "\n")


def _meant(key: str, properties: dict[str, Any]) -> str | None:
    """The key a dotted or differently spelt one means: ruff's ``lint.select``
    (``ruff config`` takes its nested keys so), the pyproject's full
    ``tool.usdrender-lint.select``, an entry ``severity.SE003`` or
    ``rules.SE001``, ``Extend_Select``; None when it means none."""
    from ..config import TOOL_TABLE

    bare = key.strip()
    for prefix in (f"tool.{TOOL_TABLE}.", "lint."):
        bare = bare.removeprefix(prefix)
    for meant in (bare, bare.partition(".")[0], bare.lower().replace("_", "-")):
        if meant in properties:
            return meant
    return None


@click.command("config")
@click.argument("key", required=False)
@format_option("config")
def config_command(key: str | None, output_format: str) -> None:
    """List the configuration keys, or describe one (its type, default and flag)."""
    from ..config import json_schema, unknown_key_hint

    properties = json_schema()["properties"]
    if key is None:
        emit("config", output_format, [_described(k, s) for k, s in properties.items()])
        return
    if key not in properties:
        near = _meant(key, properties)
        hint = f" (did you mean {near!r}?)" if near else unknown_key_hint(key)
        raise ToolError(f"no configuration key {key!r}{hint} (see 'usdrender-lint config')")
    emit("config", output_format, _described(key, properties[key]))
