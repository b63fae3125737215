"""``usdrender-lint config [KEY]``: the configuration keys and what each takes, as
``ruff config`` lists its settings. Read from the settings table and the JSON
Schema made from it (config.json_schema), so it cannot disagree with the parser;
the rules' options (``rules.CODE.OPTION``) from their Options classes and
docstrings, as ``explain`` reads them (explain.rule_options)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, TextIO

import click

from .output import ToolError
from .views import emit, format_option, view

if TYPE_CHECKING:
    from ..api import Rule
    from ..explain import RuleOption

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
    return list(value) if isinstance(value, (tuple, frozenset)) else value


def _rule_options(rules: list[type[Rule]]) -> list[dict[str, Any]]:
    """Every option of ``rules``, described as a key is (``rules.CODE.OPTION``)."""
    from ..explain import rule_options

    return [_option(rule, option) for rule in rules for option in rule_options(rule)]


def _option(rule: type[Rule], option: RuleOption) -> dict[str, Any]:
    import dataclasses
    import json

    if option.default is dataclasses.MISSING:
        default = "none"
    else:
        try:
            default = json.dumps(_plain(option.default))
        except (TypeError, ValueError):  # a plugin's default TOML cannot spell
            default = repr(option.default)
    return {
        "key": f"rules.{rule.code}.{option.name}",
        # The rule's table may name it by code or by name: [rules.SE001], [rules.<name>].
        "description": option.doc or f"An option of {rule.code} ({rule.name}).",
        "type": option.kind,
        "default": default,
        "flag": None,
        "extend": _EXTENDED["replaced"],
    }


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
        width = max((len(d["key"]) for d in described), default=0)
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
    """List the configuration keys and the rules' options, or describe one (its
    type, default and flag)."""
    from ..config import json_schema, unknown_key_hint
    from .loading import registry

    properties = json_schema()["properties"]
    if key is None:
        keys = [_described(k, s) for k, s in properties.items()]
        emit("config", output_format, keys + _rule_options(list(registry().rules)))
        return
    if key not in properties and (option := _option_key(key)) is not None:
        emit("config", output_format, _option_described(*option))
        return
    if key not in properties:
        near = _meant(key, properties)
        hint = f" (did you mean {near!r}?)" if near else unknown_key_hint(key)
        raise ToolError(f"no configuration key {key!r}{hint} (see 'usdrender-lint config')")
    emit("config", output_format, _described(key, properties[key]))


def _option_key(key: str) -> tuple[str, str] | None:
    """The rule and option a ``rules.RULE[.OPTION]`` key names (its rule by code
    or name, as a configuration's table does); None for another key."""
    from ..config import TOOL_TABLE

    bare = key.strip()
    for prefix in (f"tool.{TOOL_TABLE}.", "lint."):
        bare = bare.removeprefix(prefix)
    if not bare.startswith("rules."):
        return None
    rule, _, option = bare.removeprefix("rules.").partition(".")
    return rule, option


def _option_described(name: str, option: str) -> list[dict[str, Any]] | dict[str, Any]:
    """A rule's options (``rules.RULE``), or one of them (``rules.RULE.OPTION``)."""
    from .loading import registry

    rule = registry().find(name)
    if rule is None:
        raise ToolError(f"no rule has the code or name {name!r} (see 'usdrender-lint rules')")
    options = _rule_options([rule])
    if not options:
        raise ToolError(f"{rule.code} ({rule.name}) takes no options")
    if not option:
        return options
    for described in options:
        if described["key"].rpartition(".")[2] == option.replace("_", "-"):
            return described
    known = ", ".join(d["key"].rpartition(".")[2] for d in options)
    raise ToolError(f"{rule.code} ({rule.name}) has no option {option!r} (known: {known})")
