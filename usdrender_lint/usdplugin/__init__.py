"""usdrender-lint as an OpenUSD UsdValidation plugin: what the plugin declares.

USD reads validator metadata from a static ``plugInfo.json``; the rules come
from entry points (third-party rules too), so the file is generated from the
rule registry (``usdrender-lint plugin-path --write``) and a test fails when
the shipped one differs. Every rule becomes the validator
``usdRenderLint:<RuleName>`` (the rule's kebab-case name in PascalCase); rules
with ``prim_types`` are prim validators limited to those schema types, the
others stage validators. The validators themselves live in :mod:`.validators`,
which the ``usdRenderLint`` module (the module this plugin names) imports.

This module imports no UsdValidation and registers nothing.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..api import Rule, schemas

#: The Plug plugin name: validator names are ``<PLUGIN_NAME>:<ValidatorName>``
#: and USD imports the Python module of this name to register them.
PLUGIN_NAME = "usdRenderLint"
PLUG_INFO = "plugInfo.json"
#: Every validator carries this keyword; its family adds ``usdRenderLint:<PREFIX>``.
KEYWORD = PLUGIN_NAME


def plugin_dir() -> Path:
    """The shipped plugin directory (point ``PXR_PLUGINPATH_NAME`` at it)."""
    return Path(__file__).resolve().parent


def validator_key(rule: type[Rule]) -> str:
    """The rule's name in PascalCase: ``data-window-malformed`` -> ``DataWindowMalformed``."""
    return "".join(part[:1].upper() + part[1:] for part in rule.name.split("-"))


def validator_name(rule: type[Rule]) -> str:
    return f"{PLUGIN_NAME}:{validator_key(rule)}"


def family(rule: type[Rule]) -> str:
    """The code's letter prefix: ``SE`` for ``SE003``."""
    return rule.code.rstrip("0123456789")


def schema_type_names(rule: type[Rule]) -> list[str]:
    """USD's type names for the rule's schema classes (``UsdRenderSettingsBase``)."""
    return [schemas.tf_type(schema).typeName for schema in rule.prim_types]


def is_prim_validator(rule: type[Rule]) -> bool:
    """A rule that checks prims of its ``prim_types`` and nothing else. One
    that also has ``check_stage`` is a stage validator: USD calls a prim
    validator only on its prims, so its stage-wide findings would be lost."""
    return bool(rule.prim_types) and rule.check_stage is Rule.check_stage


def validator_entry(rule: type[Rule]) -> dict[str, Any]:
    entry: dict[str, Any] = {
        # The summary only: the full doc is `usdrender-lint explain CODE`.
        "doc": f"{rule.code} ({rule.name}): {rule.summary() or rule.name}",
        "keywords": [f"{KEYWORD}:{family(rule)}", f"{KEYWORD}:{rule.code}"],
    }
    if is_prim_validator(rule):
        entry["schemaTypes"] = schema_type_names(rule)
    return entry


class DeclarationError(ValueError):
    """Two rules would get the same validator name."""


def plug_info(rules: Sequence[type[Rule]]) -> dict[str, Any]:
    """The ``plugInfo.json`` content declaring ``rules`` as validators."""
    validators: dict[str, Any] = {"keywords": [KEYWORD]}
    owners: dict[str, str] = {}
    for rule in sorted(rules, key=lambda r: r.code):
        key = validator_key(rule)
        if key in owners:
            raise DeclarationError(
                f"rules {owners[key]} and {rule.code} both map to validator {PLUGIN_NAME}:{key}"
            )
        owners[key] = rule.code
        validators[key] = validator_entry(rule)
    return {
        "Plugins": [
            {
                # "python": USD imports the module named PLUGIN_NAME on first use.
                "Type": "python",
                "Name": PLUGIN_NAME,
                "Info": {"Validators": validators},
            }
        ]
    }


def render_plug_info(rules: Sequence[type[Rule]]) -> str:
    return json.dumps(plug_info(rules), indent=4, ensure_ascii=False) + "\n"


def shipped_plug_info(directory: Path | None = None) -> str | None:
    """The text of the ``plugInfo.json`` in ``directory`` (default: the
    shipped one), or None when there is none."""
    try:
        return ((directory or plugin_dir()) / PLUG_INFO).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None


def declared_validators(directory: Path | None = None) -> dict[str, Any] | None:
    """The validators the plugInfo.json in ``directory`` declares; None when
    there is no such file, or it is not JSON declaring a plugin's validators."""
    text = shipped_plug_info(directory)
    try:
        declared = json.loads(text)["Plugins"][0]["Info"]["Validators"] if text else None
    except (ValueError, KeyError, IndexError, TypeError):
        return None
    return declared if isinstance(declared, dict) else None


def undeclared_rules(rules: Sequence[type[Rule]], directory: Path | None = None) -> list[str]:
    """Codes of registered rules whose validator the plugInfo.json in
    ``directory`` lacks or declares differently (empty: it is up to date)."""
    declared = declared_validators(directory) or {}
    return [
        rule.code for rule in rules if declared.get(validator_key(rule)) != validator_entry(rule)
    ]


def write_plug_info(rules: Sequence[type[Rule]], directory: Path | None = None) -> Path:
    """Write ``plugInfo.json`` declaring ``rules`` into ``directory`` (default:
    the shipped one), atomically; returns the directory."""
    from ..atomic import write_text_atomic

    directory = directory or plugin_dir()
    directory.mkdir(parents=True, exist_ok=True)
    write_text_atomic(str(directory / PLUG_INFO), render_plug_info(rules))
    return directory


__all__ = [
    "KEYWORD",
    "PLUGIN_NAME",
    "DeclarationError",
    "declared_validators",
    "plug_info",
    "plugin_dir",
    "render_plug_info",
    "undeclared_rules",
    "validator_name",
    "write_plug_info",
]
