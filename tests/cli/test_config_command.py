"""``usdrender-lint config [KEY]``: the configuration keys, as ``ruff config`` lists its."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.config import json_schema
from usdrender_lint.settings_table import BY_CONFIG_KEY


def run(*args: str):
    return CliRunner().invoke(cli, ["config", *args])


def test_every_key_is_listed_with_its_description() -> None:
    result = run()
    assert result.exit_code == 0, result.output
    listed = [line.split()[0] for line in result.stdout.splitlines()]
    assert listed == list(json_schema()["properties"])
    assert set(listed) == set(BY_CONFIG_KEY)
    assert any(line.startswith("per-path-ignores ") for line in result.stdout.splitlines())


def test_a_key_says_its_type_default_flag_and_how_extend_treats_it() -> None:
    result = run("fail-on")
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines() == [
        "fail-on: Lowest severity that makes the exit code 1",
        "",
        'Type: one of "error", "warning", "info", "never"',
        "Default: error",
        "Flag: --fail-on",
        "In a file that extends another, it replaces the extended file's value.",
    ]
    table = run("per-path-ignores").stdout
    assert "Type: a table" in table and "merges with the extended file's table" in table
    assert "Flag:" not in table  # configuration files only
    assert "Default: every rule" in run("select").stdout
    assert "Type: an integer of at least 1" in run("time-sample-cap").stdout


def test_the_json_view_holds_what_the_text_says() -> None:
    everything = json.loads(run("--format", "json").stdout)
    assert [d["key"] for d in everything] == list(json_schema()["properties"])
    one = json.loads(run("--format", "json", "variants").stdout)
    assert one == {
        "key": "variants",
        "description": BY_CONFIG_KEY["variants"].help,
        "type": "a boolean",
        "default": "false",
        "flag": "--variants",
        "extend": "replaces the extended file's value",
    }


def test_an_unknown_key_is_one_line_naming_the_nearest() -> None:
    result = run("per-file-ignores")
    assert result.exit_code == 2
    assert result.stderr == (
        "usdrender-lint: error: no configuration key 'per-file-ignores' "
        "(did you mean 'per-path-ignores'?) (see 'usdrender-lint config')\n"
    )
    assert result.stdout == ""


def test_the_profile_keys_name_every_profile() -> None:
    """Before, `config profile` said "Type: a string": the names were nowhere but
    in the error of a run that named a wrong one."""
    from usdrender_lint.profiles import PROFILES

    names = ", ".join(f'"{name}"' for name in ["auto", *PROFILES])
    assert f"Type: one of {names}\n" in run("profile").stdout
    assert f"Type: a table of file globs, each to one of {names}\n" in (
        run("per-path-profiles").stdout
    )


@pytest.mark.parametrize(
    ("given", "meant"),
    [
        ("lint.select", "select"),  # as `ruff config lint.select` takes it
        ("tool.usdrender-lint.per-path-ignores", "per-path-ignores"),
        ("severity.SE003", "severity"),
        ("rules.SE001", "rules"),
        ("rules.SE001.require-authored", "rules"),
        ("Extend_Select", "extend-select"),
        (" fail-on ", "fail-on"),
    ],
)
def test_a_dotted_or_ruff_spelt_key_names_the_one_it_means(given: str, meant: str) -> None:
    """Before, these said only "no configuration key" with no key to try."""
    result = run(given)
    assert result.exit_code == 2
    assert result.stderr == (
        f"usdrender-lint: error: no configuration key {given!r} (did you mean {meant!r}?) "
        "(see 'usdrender-lint config')\n"
    )
