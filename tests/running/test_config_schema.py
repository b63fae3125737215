"""The configuration's JSON Schema (config.json_schema, published on the docs
site as config-schema.json): derived from the settings table, it accepts every
configuration the reader accepts, and rejects the wrong types and unknown keys
the reader rejects."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path
from typing import Any

import pytest
from test_settings_table import SAMPLES  # the same sample of every key

from usdrender_lint.config import ConfigError, json_schema, read_config_file
from usdrender_lint.settings_table import SETTINGS

jsonschema = pytest.importorskip("jsonschema")

REPO = Path(__file__).resolve().parents[2]
SCHEMA = json_schema()
KEYS = [entry.config_key for entry in SETTINGS if entry.config_key]


def _valid(document: dict[str, Any]) -> bool:
    return jsonschema.Draft4Validator(SCHEMA).is_valid(document)


def _reads(tmp_path: Path, text: str) -> bool:
    path = tmp_path / ".usdrender-lint.toml"
    path.write_text(text, encoding="utf-8")
    (tmp_path / "base.toml").write_text("")  # what the sample of extend names
    try:
        read_config_file(path)
    except ConfigError:
        return False
    return True


def test_it_is_a_valid_schema_of_every_key() -> None:
    jsonschema.Draft4Validator.check_schema(SCHEMA)
    assert set(SCHEMA["properties"]) == set(KEYS)


@pytest.mark.parametrize("key", KEYS)
def test_every_sample_value_the_reader_reads_is_valid(key: str, tmp_path: Path) -> None:
    text = f"{key} = {SAMPLES[key][0]}\n"
    assert _reads(tmp_path, text)
    assert _valid(tomllib.loads(text))


#: A value of the wrong type for each kind of key.
WRONG = {"array": "{ a = 1 }", "string": "3", "boolean": '"yes"', "integer": '"7"', "object": "3"}


@pytest.mark.parametrize("key", KEYS)
def test_a_value_of_the_wrong_type_is_refused_by_both(key: str, tmp_path: Path) -> None:
    kind = _kind(SAMPLES[key][0])
    text = f"{key} = {WRONG[kind]}\n"
    assert not _reads(tmp_path, text)
    assert not _valid(tomllib.loads(text))


def _kind(sample: str) -> str:
    value = tomllib.loads(f"x = {sample}")["x"]
    names = {list: "array", str: "string", bool: "boolean", int: "integer", dict: "object"}
    return names[type(value)]


@pytest.mark.parametrize(
    ("text", "reads"),
    [
        ("time-sample-cap = 0", False),
        ("time-sample-cap = 1", True),
        ("max-variant-combinations = 0", False),
        ("max-variant-combinations = 10000", True),
        ("max-variant-combinations = 10001", False),
        ('profile = ""', False),
        ('per-path-profiles = { "old/*" = "" }', False),
        ('per-path-profiles = { "old/*" = "karma" }', True),
        ('per-path-profiles = { "" = "karma" }', False),
        # An editor marks a profile no run would take (check_profiles refuses it).
        ('profile = "Karma"', "schema"),
        ('profile = "auto"', True),
        ('per-path-profiles = { "old/*" = "prman" }', "schema"),
        ('per-path-profiles = { "old/*" = "auto" }', True),
        ('per-path-profiles = { "!old/*" = "karma" }', True),
        ('per-path-ignores = { "old/*" = ["SE"] }', True),
        ('per-path-ignores = { "old/*" = "SE" }', True),
        ('per-path-ignores = { "x" = ["SE"] }', True),
        ('per-path-ignores = { "!x" = ["SE"] }', True),
        ('per-path-ignores = { "!!" = ["SE"] }', True),
        ('per-path-ignores = { " {a,} " = ["SE"] }', True),
        ('per-path-ignores = { "" = ["SE"] }', False),
        ('per-path-ignores = { "  " = ["SE"] }', False),
        ('per-path-ignores = { "!" = ["SE"] }', False),
        ('per-path-ignores = { "! " = ["SE"] }', False),
        ('per-path-ignores = { "{,}" = ["SE"] }', False),
        ('per-path-ignores = { "x" = 3 }', False),
        ('cache-dir = "  "', False),
        ('cache-dir = " x"', True),
        ('extend = ""', False),
    ],
)
def test_a_value_out_of_range_is_refused_by_both(
    tmp_path: Path, text: str, reads: bool | str
) -> None:
    """The schema says what the reader checks beyond the type: an editor marks
    the value the run would stop on."""
    if reads == "schema":  # a name only the run knows is wrong: read, then refused
        assert _reads(tmp_path, text + "\n")
        assert not _valid(tomllib.loads(text))
        return
    assert _reads(tmp_path, text + "\n") is reads
    assert _valid(tomllib.loads(text)) is reads


def test_an_unknown_key_is_refused_by_both(tmp_path: Path) -> None:
    assert not _reads(tmp_path, "selct = []\n")
    assert not _valid({"selct": []})


def test_the_guides_configurations_are_valid(tmp_path: Path) -> None:
    """Every ``.usdrender-lint.toml``-style TOML block of the configuration guide
    (the [tool.usdrender-lint] table of the pyproject ones) is valid."""
    guide = (REPO / "docs" / "guides" / "configuration.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```toml\n(.*?)```", guide, flags=re.DOTALL)
    assert len(blocks) >= 3
    for block in blocks:
        document = tomllib.loads(block)
        document = document.get("tool", {}).get("usdrender-lint", document)
        assert _valid(document), block


def test_a_severity_in_any_case_is_read_and_valid(tmp_path: Path) -> None:
    text = '[severity]\nSE003 = " Warning "\n'
    assert _reads(tmp_path, text) and _valid(tomllib.loads(text))
    assert not _valid(tomllib.loads('[severity]\nSE003 = "warn"\n'))


def _taplo() -> str:
    found = shutil.which("taplo") or shutil.which("taplo", path=str(Path(sys.executable).parent))
    if found is None:
        pytest.skip("taplo is not installed (pip install taplo; the test extra has it)")
    return found


def test_taplo_checks_a_file_with_the_schema_as_an_editor_does(tmp_path: Path) -> None:
    """taplo (the TOML toolkit of Even Better TOML) reads the schema a file names
    in its #:schema directive: the guide's file passes, and each wrong key or
    value is an error at its line."""
    (tmp_path / "config-schema.json").write_text(json.dumps(SCHEMA), encoding="utf-8")
    good = tmp_path / ".usdrender-lint.toml"
    good.write_text(
        '#:schema ./config-schema.json\nselect = ["ALL"]\nfail-on = "warning"\n'
        '[severity]\nSE015 = "Info"\n[rules.resolution-non-positive]\nrequire-authored = true\n'
    )
    bad = tmp_path / "bad.toml"
    bad.write_text(
        '#:schema ./config-schema.json\nfail-on = "sometimes"\nselct = []\n'
        'variants = "yes"\n[severity]\nSE015 = "loud"\n'
    )
    assert _reads(tmp_path, good.read_text())
    checked = subprocess.run(
        [_taplo(), "check", "--no-auto-config", "--colors", "never", str(good)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert checked.returncode == 0, checked.stderr
    refused = subprocess.run(
        [_taplo(), "check", "--no-auto-config", "--colors", "never", str(bad)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert refused.returncode != 0
    for line in (2, 4, 6):
        assert f"bad.toml:{line}:" in refused.stderr, refused.stderr
    assert "selct" in refused.stderr
