"""The settings table (usdrender_lint/settings_table.py) declares each setting
once; the configuration parser, the command line's flags, the pipeline's
Request, the Python API and the result cache's key derive from it. Each test
fails when a setting is missing from one of them."""

from __future__ import annotations

import dataclasses
import inspect
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

import usdrender_lint
from usdrender_lint.cli import cli
from usdrender_lint.config import ConfigError, Settings, read_config_file
from usdrender_lint.running.inspect import InspectRequest
from usdrender_lint.running.pipeline import Request, resolve_settings
from usdrender_lint.running.result_cache import settings_key
from usdrender_lint.settings_table import BY_NAME, SETTINGS, flag_settings, request_settings

REPO = Path(__file__).resolve().parents[2]
CLEAN = REPO / "examples" / "clean_shot" / "shot.usda"

#: A valid configuration value of every configuration key (TOML) and the
#: Settings value it gives. A new key without a sample fails the tests below.
SAMPLES: dict[str, tuple[str, Any]] = {
    "select": ('["SE", "CA001"]', ("SE", "CA001")),
    "ignore": ('["SE002"]', ("SE002",)),
    "extend-select": ('["PA"]', ("PA",)),
    "fail-on": ('"warning"', "warning"),
    "severity": ('{ SE002 = "warning" }', None),
    "per-path-ignores": ('{ "a/*.usda" = ["SE"] }', {"a/*.usda": ("SE",)}),
    "rules": ("{ SE001 = { require-authored = true } }", {"SE001": {"require-authored": True}}),
    "roots": ('["shots/*.usda"]', ("shots/*.usda",)),
    "time-sample-cap": ("7", 7),
    "unfixable": ('["CA004"]', ("CA004",)),
    "variants": ("true", True),
    "max-variant-combinations": ("9", 9),
    "profile": ('"karma"', "karma"),
    "per-path-profiles": ('{ "a/*.usda" = "arnold" }', {"a/*.usda": "arnold"}),
    "cache-dir": ('"build/cache"', "build/cache"),
    "exclude": ('["build"]', ("build",)),
    "extend-exclude": ('["wip/*.usda"]', ("wip/*.usda",)),
    "respect-gitignore": ("false", False),
    "force-exclude": ("true", True),
    # (the test writes an empty base.toml beside the file; tests/running/test_config_extend.py)
    "extend": ('"base.toml"', None),
}

#: Settings' fields that say where values came from, not values; and the layers
#: of rule selection beneath the keys (``select``, ``ignore``, ``extend-select``).
_ORIGINS = {
    "source",
    "user_level",
    "from_flags",
    "from_file",
    "sources",
    "selections_below",
    "entries_from",
}
_CONFIG_NAMES = {f.name for f in dataclasses.fields(Settings)} - _ORIGINS


def test_every_settings_field_is_a_table_setting_with_its_default() -> None:
    table = {s.name: s for s in SETTINGS if s.config_key}
    assert set(table) == _CONFIG_NAMES
    defaults = Settings()
    for name, entry in table.items():
        assert getattr(defaults, name) == entry.default, name


@pytest.mark.parametrize("entry", [s for s in SETTINGS if s.config_key], ids=lambda s: s.name)
def test_every_config_key_is_read(entry, tmp_path: Path) -> None:
    text, expected = SAMPLES[entry.config_key]
    path = tmp_path / ".usdrender-lint.toml"
    path.write_text(f"{entry.config_key} = {text}\n")
    (tmp_path / "base.toml").write_text("")
    value = getattr(read_config_file(path), entry.name)
    if expected is not None:
        assert value == expected
    assert value != entry.default


def test_every_flag_is_an_option_of_its_commands() -> None:
    for entry in SETTINGS:
        if entry.flag is None:
            continue
        for command in entry.commands:
            params = cli.commands[command].params
            flags = {flag for param in params for flag in param.opts}
            assert entry.flag in flags, (command, entry.flag)


def test_a_flag_no_configuration_sets_is_off_not_none_when_not_given() -> None:
    # None means "the configuration decides"; with no configuration key the
    # flag's value is its default, as the Request's bool annotation says.
    for command in ("check", "spec"):
        params = {p.name: p for p in cli.commands[command].params}
        for entry in flag_settings(command):
            if entry.kind != "flag":
                continue
            expected = None if entry.config_key else entry.default
            assert params[entry.name].default is expected, (command, entry.name)
    assert any(e.kind == "flag" and not e.config_key for e in flag_settings("check"))


def test_every_request_setting_is_a_request_field() -> None:
    fields = {f.name for f in dataclasses.fields(Request)}
    assert {s.name for s in request_settings()} <= fields
    inspect_fields = {f.name for f in dataclasses.fields(InspectRequest)}
    assert {s.name for s in flag_settings("spec")} <= inspect_fields


def test_every_config_setting_a_request_gives_wins_over_or_adds_to_the_file(tmp_path: Path) -> None:
    path = tmp_path / ".usdrender-lint.toml"
    given = {}
    lines = []
    for entry in request_settings():
        if entry.config_key:
            lines.append(f"{entry.config_key} = {SAMPLES[entry.config_key][0]}")
            given[entry.name] = entry.default if entry.default is not None else ("CA",)
    path.write_text("\n".join(lines) + "\n")
    settings = resolve_settings(Request((str(CLEAN),), config=str(path), **given))
    for name, value in given.items():
        entry = BY_NAME[name]
        if entry.extended == "added":
            # As ruff's --extend-exclude: added to the file's list.
            value = (*SAMPLES[entry.config_key][1], *value)
        assert getattr(settings, name) == value, name


def test_every_api_setting_is_a_keyword_of_the_python_api() -> None:
    for function in (usdrender_lint.lint_file, usdrender_lint.lint_stage):
        keywords = set(inspect.signature(function).parameters)
        wanted = {s.name for s in SETTINGS if s.api}
        if function is usdrender_lint.lint_stage:
            wanted -= {"variants", "max_variant_combinations"}  # files only (see its doc)
        assert wanted <= keywords, function.__name__


def test_the_cache_key_holds_exactly_the_settings_that_change_findings() -> None:
    key = settings_key(Settings())
    assert set(key) == {s.name for s in SETTINGS if s.config_key and s.changes_findings}


def test_a_value_is_checked_alike_from_a_flag_a_file_and_the_api(tmp_path: Path) -> None:
    said = CliRunner().invoke(
        cli, ["check", "--isolated", "--max-variant-combinations", "0", str(CLEAN)]
    )
    assert said.exit_code == 2
    path = tmp_path / ".usdrender-lint.toml"
    path.write_text("max-variant-combinations = 0\n")
    with pytest.raises(ConfigError) as from_file:
        read_config_file(path)
    with pytest.raises(ConfigError) as from_api:
        usdrender_lint.lint_file(CLEAN, max_variant_combinations=0)
    reason = "must be a whole number from 1 to 10000, got 0"
    assert reason in said.output and reason in str(from_file.value)
    assert reason in str(from_api.value)


def test_the_api_keywords_the_table_adds_change_the_lint() -> None:
    broken = REPO / "examples" / "broken_shot" / "shot.usda"
    chosen = usdrender_lint.lint_file(broken, profile="karma")
    assert chosen.findings and {f.profile for f in chosen.findings} == {"karma"}
    only_ca = usdrender_lint.lint_file(broken, select=["CA"])
    widened = usdrender_lint.lint_file(broken, select=["CA"], extend_select=["SE"])
    assert {f.code[:2] for f in only_ca.findings} == {"CA"}
    assert {f.code[:2] for f in widened.findings} >= {"CA", "SE"}
