"""``usdrender-lint config [KEY]``: the configuration keys, as ``ruff config`` lists its."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.config import json_schema
from usdrender_lint.registry import build_registry
from usdrender_lint.settings_table import BY_CONFIG_KEY

ACME_PLUGIN = Path(__file__).parents[2] / "examples" / "acme-plugin"


def run(*args: str):
    return CliRunner().invoke(cli, ["config", *args])


def test_every_key_is_listed_with_its_description() -> None:
    result = run()
    assert result.exit_code == 0, result.output
    listed = [line.split()[0] for line in result.stdout.splitlines()]
    keys = [key for key in listed if not key.startswith("rules.")]  # the rules' options
    assert keys == list(json_schema()["properties"]) == listed[: len(keys)]
    assert set(keys) == set(BY_CONFIG_KEY)
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
    keys = list(json_schema()["properties"])
    assert [d["key"] for d in everything][: len(keys)] == keys
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


def test_every_rule_option_is_listed_as_explain_reads_it() -> None:
    """Before, `config` listed no rule's options: only `explain RULE` named them."""
    from usdrender_lint.explain import rule_options

    listed = {d["key"]: d for d in json.loads(run("--format", "json").stdout)}
    for rule in build_registry().rules:
        for option in rule_options(rule):
            described = listed.pop(f"rules.{rule.code}.{option.name}")
            assert described["type"] == option.kind
            assert described["description"] == option.doc, rule.code
    assert not [key for key in listed if key.startswith("rules.")]
    assert "rules.SE001.require-authored  also report a RenderSettings whose `resolution` is " in (
        run().stdout
    )
    assert run("rules.resolution-non-positive.require_authored").stdout.splitlines()[2:] == [
        "Type: bool",
        "Default: false",
        "In a file that extends another, it replaces the extended file's value.",
    ]
    # The options of one rule, by its code or name, as a [rules.RULE] table names it.
    everything = json.loads(run("--format", "json").stdout)
    assert json.loads(run("--format", "json", "rules.lpe-malformed").stdout) == [
        d for d in everything if d["key"].startswith("rules.VA003.")
    ]


@pytest.mark.parametrize(
    ("key", "said"),
    [
        ("rules.XX999", "no rule has the code or name 'XX999' (see 'usdrender-lint rules')"),
        ("rules.SE002", "SE002 (pixel-aspect-ratio-invalid) takes no options"),
        (
            "rules.SE001.require",
            "SE001 (resolution-non-positive) has no option 'require' (known: require-authored)",
        ),
    ],
)
def test_a_rule_option_that_does_not_exist_is_one_line(key: str, said: str) -> None:
    result = run(key)
    assert (result.exit_code, result.stdout, result.stderr) == (
        2,
        "",
        f"usdrender-lint: error: {said}\n",
    )


def test_a_plugin_rule_s_options_are_listed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The example plugin's ACME001 takes a `token`: `config` never said so."""
    info = tmp_path / "acme_render_rules-1.0.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: acme-render-rules\nVersion: 1.0.0\n"
    )
    (info / "entry_points.txt").write_text(
        "[usdrender_lint.rules]\nacme = acme_render_rules:RULES\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.syspath_prepend(str(ACME_PLUGIN))
    listed = {d["key"]: d for d in json.loads(run("--format", "json").stdout)}
    assert listed["rules.ACME001.token"] == {
        "key": "rules.ACME001.token",
        "description": 'the frame token the farm expands, e.g. `"$F4"` for a farm that reads '
        "Houdini's variables.",
        "type": "str",
        "default": '"####"',
        "flag": None,
        "extend": "replaces the extended file's value",
    }
    assert run("rules.product-name-frame-token.token").stdout.startswith(
        'rules.ACME001.token: the frame token the farm expands, e.g. `"$F4"`'
    )
