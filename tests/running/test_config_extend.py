"""``extend``: a configuration file that starts from another's settings (a
show's on top of a studio's). Each key it sets replaces the extended value;
tables merge entry by entry; ``extend-select`` and ``extend-exclude`` add.
A chain of files gives the findings of the one flat file ``--show-settings``
prints for it."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.config import (
    MAX_EXTEND_DEPTH,
    ConfigError,
    Settings,
    load_settings,
    read_config_file,
)
from usdrender_lint.registry import build_registry
from usdrender_lint.running.documents import Documents
from usdrender_lint.running.pipeline import make_rules, profile_chooser

REPO = Path(__file__).resolve().parents[2]
BROKEN = REPO / "examples" / "broken_shot" / "shot.usda"

STUDIO = """\
select = ["CA", "SE", "PR"]
extend-select = ["ST"]
fail-on = "warning"
extend-exclude = ["reference/"]
time-sample-cap = 50

[severity]
SE003 = "warning"
CA003 = "info"

[per-path-ignores]
"*_wip.usda" = ["ALL"]

[rules.resolution-non-positive]
require-authored = true
"""

SHOW = """\
extend = "../studio/studio.toml"
ignore = ["CA009"]
extend-exclude = ["old/"]
time-sample-cap = 12

[severity]
CA003 = "error"

[rules.resolution-non-positive]
"""


@pytest.fixture
def show(tmp_path: Path) -> Path:
    (tmp_path / "studio").mkdir()
    (tmp_path / "studio" / "studio.toml").write_text(STUDIO)
    root = tmp_path / "show"
    (root / "shots").mkdir(parents=True)
    shutil.copy(BROKEN, root / "shots" / "shot.usda")
    (root / ".usdrender-lint.toml").write_text(SHOW)
    return root


def test_each_key_replaces_merges_or_adds(show: Path) -> None:
    settings = read_config_file(show / ".usdrender-lint.toml")
    studio = str(show.parent / "studio" / "studio.toml")
    # The rule selection is layered, as ruff's: the show's ignore over the studio's choice.
    (studio_layer,) = settings.selections_below
    assert (studio_layer.select, studio_layer.ignore, studio_layer.extend_select) == (
        ("CA", "SE", "PR"),
        (),
        ("ST",),
    )
    assert studio_layer.origins["select"] == f"{studio}: select"
    assert (settings.select, settings.ignore, settings.extend_select) == (None, ("CA009",), ())
    assert settings.time_sample_cap == 12  # replaced
    assert settings.extend_exclude == ("reference/", "old/")  # added
    assert {k: v.value for k, v in settings.severity.items()} == {
        "SE003": "warning",
        "CA003": "error",  # merged: this file's entry wins
    }
    assert settings.per_path_ignores == {"*_wip.usda": ("ALL",)}
    assert settings.rule_options == {"resolution-non-positive": {"require-authored": True}}
    assert settings.source == str(show / ".usdrender-lint.toml")
    assert settings.sources == (settings.source, studio)
    assert settings.extend == studio
    assert settings.from_file["fail_on"] == studio
    assert settings.from_file["ignore"] == settings.source
    # Relative globs stay the found file's: its folder is the base.
    assert settings.base_dir == show


def _chosen(settings: Settings) -> set[str]:
    return {type(rule).code for rule in make_rules(build_registry(), settings)}


def test_a_select_of_its_own_starts_the_selection_over(show: Path) -> None:
    (show / ".usdrender-lint.toml").write_text('select = ["SE003"]\n' + SHOW)
    settings = read_config_file(show / ".usdrender-lint.toml")
    assert (settings.select, settings.extend_select) == (("SE003",), ())
    assert _chosen(settings) == {"SE003"}


def test_each_layer_starts_from_what_the_one_beneath_chose(show: Path) -> None:
    """As ruff layers rule selections: the extending file's ``ignore`` and
    ``extend-select`` change only the rules they name, over the studio's choice."""
    settings = read_config_file(show / ".usdrender-lint.toml")
    chosen = _chosen(settings)
    assert "CA009" not in chosen and {"CA001", "SE003", "PR004", "ST002"} <= chosen
    assert not any(code.startswith(("VA", "PA")) for code in chosen)
    # An ignore of the studio's is not undone by the show's own ignore ...
    studio = show.parent / "studio" / "studio.toml"
    studio.write_text(STUDIO.replace('select = ["CA", "SE", "PR"]', 'ignore = ["PR004"]'))
    assert not {"PR004", "CA009"} & _chosen(read_config_file(show / ".usdrender-lint.toml"))
    # ... but an extend-select of the show's brings back what the studio ignores.
    (show / ".usdrender-lint.toml").write_text('extend-select = ["PR"]\n' + SHOW)
    assert "PR004" in _chosen(read_config_file(show / ".usdrender-lint.toml"))


def test_a_chain_gives_the_findings_of_its_flat_settings(show: Path, tmp_path: Path) -> None:
    """Three files deep (a pyproject.toml in the middle, ~ in a path): the
    findings are those of the single file --show-settings prints for it."""
    home = tmp_path / "home"
    home.mkdir()
    (tmp_path / "studio" / "studio.toml").write_text('extend = "~/base.toml"\n' + STUDIO)
    (home / "base.toml").write_text('profile = "karma"\n[severity]\nPR004 = "info"\n')
    (show / ".usdrender-lint.toml").unlink()
    (show / "pyproject.toml").write_text(
        "[tool.usdrender-lint]\n" + SHOW.replace("[severity]", "[tool.usdrender-lint.severity]")
    )
    os.environ["HOME"] = str(home)  # restored by the fixture below
    runner = CliRunner()
    previous = os.getcwd()
    os.chdir(show)
    try:
        shown = runner.invoke(cli, ["check", "--show-settings", "."])
        assert shown.exit_code == 0, shown.output
        assert f"# which extends: {home / 'base.toml'}" in shown.stdout
        assert 'profile = "karma"  # file ' + str(home / "base.toml") in shown.stdout
        flat = tmp_path / "flat.toml"
        flat.write_text(shown.stdout)
        args = ["check", "--no-cache", "--format", "json", "--show-info", "."]
        chained = runner.invoke(cli, args)
        flattened = runner.invoke(cli, [*args[:-1], "--config", str(flat), "."])
    finally:
        os.chdir(previous)
    assert chained.exit_code == flattened.exit_code == 1
    found = json.loads(chained.stdout)["files"]
    # The same findings; a profile's reason names the file that set it.
    reasons = {f.pop("profile_reason") for entry in found for f in entry["findings"]}
    assert reasons == {f"{home / 'base.toml'}: profile = karma"}
    flat_found = json.loads(flattened.stdout)["files"]
    for entry in flat_found:
        for finding in entry["findings"]:
            assert finding.pop("profile_reason") == f"{flat}: profile = karma"
    # Each report names the file it was linted under.
    assert {entry.pop("config_file") for entry in found} == {"pyproject.toml"}
    assert {entry.pop("config_file") for entry in flat_found} == {str(flat)}
    assert found == flat_found
    codes = {f["code"]: f["severity"] for entry in found for f in entry["findings"]}
    assert codes["PR004"] == "info" and codes["SE003"] == "warning"


def test_extend_expands_environment_variables(show: Path, monkeypatch) -> None:
    """As ruff's extend: "User home directory and environment variables will be
    expanded" (a studio names its file by $STUDIO_CONFIG, set per site)."""
    monkeypatch.setenv("STUDIO_CONFIG", str(show.parent / "studio"))
    (show / ".usdrender-lint.toml").write_text('extend = "${STUDIO_CONFIG}/studio.toml"\n')
    settings = load_settings(start=str(show / "shots"))
    assert settings.extend == str(show.parent / "studio" / "studio.toml")
    assert settings.time_sample_cap == 50
    monkeypatch.delenv("STUDIO_CONFIG")
    result = CliRunner().invoke(cli, ["check", "--no-cache", str(show / "shots")])
    assert result.exit_code == 2 and len(result.stderr.splitlines()) == 1
    assert "'extend': environment variable STUDIO_CONFIG is not set" in result.stderr


def test_a_chain_too_long_is_one_line_not_an_internal_error(tmp_path: Path) -> None:
    """Each extended file is read inside the one extending it: a chain of a few
    hundred files overflowed the stack. Up to MAX_EXTEND_DEPTH are read."""
    for count, fine in [(MAX_EXTEND_DEPTH, True), (400, False)]:
        folder = tmp_path / str(count)
        folder.mkdir()
        for i in range(count - 1):
            (folder / f"c{i}.toml").write_text(f'extend = "c{i + 1}.toml"\n')
        (folder / f"c{count - 1}.toml").write_text("time-sample-cap = 7\n")
        if fine:
            assert read_config_file(folder / "c0.toml").time_sample_cap == 7
            continue
        args = ["check", "--no-cache", "--config", str(folder / "c0.toml"), str(BROKEN)]
        result = CliRunner().invoke(cli, args)
        assert result.exit_code == 2 and len(result.stderr.splitlines()) == 1, result.output
        assert f"more than {MAX_EXTEND_DEPTH} files extend each other" in result.stderr


def test_a_rules_options_merge_when_one_file_names_it_by_code_the_other_by_name(
    show: Path,
) -> None:
    """The studio's [rules.lpe-malformed] and the show's [rules.VA003] are one
    rule's options, merged option by option: the studio's extra-labels stay."""
    (show.parent / "studio" / "studio.toml").write_text(
        '[rules.lpe-malformed]\nextra-labels = ["myLabel"]\ndialect = "osl"\n'
    )
    (show / ".usdrender-lint.toml").write_text(
        'extend = "../studio/studio.toml"\n[rules.VA003]\ndialect = "extended"\n'
    )
    settings = load_settings(start=str(show / "shots"))
    rule = next(r for r in make_rules(build_registry(), settings) if r.code == "VA003")
    assert rule.options.extra_labels == ("myLabel",)
    assert rule.options.dialect == "extended"


def test_a_later_layer_wins_for_a_rule_spelt_otherwise_beneath(show: Path) -> None:
    """The studio names the rule, the show its code, an inline --config the name
    again: the inline setting, the last layer, decides."""
    (show.parent / "studio" / "studio.toml").write_text('[severity]\ncamera-unset = "info"\n')
    (show / ".usdrender-lint.toml").write_text(
        'extend = "../studio/studio.toml"\n[severity]\nCA001 = "warning"\n'
    )
    (show / "shots" / "shot.usda").write_text(
        '#usda 1.0\ndef RenderSettings "S"\n{\n    rel products = </P>\n}\n'
        'def RenderProduct "P"\n{\n}\n'
    )
    args = ["check", "--no-cache", "--format", "json", "--select", "CA001"]
    inline = ["--config", 'severity.camera-unset = "error"']
    for extra, severity in [([], "warning"), (inline, "error")]:
        result = CliRunner().invoke(cli, [*args, *extra, str(show / "shots")])
        found = json.loads(result.stdout)["files"][0]["findings"]
        assert [(f["code"], f["severity"]) for f in found] == [("CA001", severity)], extra


def test_the_extending_files_per_path_profile_wins_over_the_extended_catch_all(
    show: Path,
) -> None:
    """The studio maps every file to karma, the show its shots to renderman:
    the show's glob is tried first (within one file, the first glob still wins)."""
    (show.parent / "studio" / "studio.toml").write_text('[per-path-profiles]\n"**" = "karma"\n')
    own = '[per-path-profiles]\n"shots/*" = "renderman"\n'
    (show / ".usdrender-lint.toml").write_text(f'extend = "../studio/studio.toml"\n{own}')
    shot = str(show / "shots" / "shot.usda")
    choose = profile_chooser(load_settings(start=str(show / "shots")))
    assert choose(shot)[0] == "renderman"
    # --show-settings prints the globs in that order: the flat file chooses alike
    shown = CliRunner().invoke(cli, ["check", "--show-settings", str(show / "shots")])
    flat = show / "flat.toml"  # beside the show's: its globs read from the same folder
    flat.write_text(shown.stdout)
    assert profile_chooser(read_config_file(flat))(shot)[0] == "renderman"
    (show / ".usdrender-lint.toml").write_text('[per-path-profiles]\n"**" = "karma"\n' + own[20:])
    assert profile_chooser(load_settings(start=str(show / "shots")))(shot)[0] == "karma"


def test_a_per_path_profiles_reason_names_the_file_of_its_glob(show: Path) -> None:
    studio = show.parent / "studio" / "studio.toml"
    studio.write_text('[per-path-profiles]\n"**" = "karma"\n')
    (show / ".usdrender-lint.toml").write_text(
        'extend = "../studio/studio.toml"\n[per-path-profiles]\n"old/*" = "renderman"\n'
    )
    shot = str(show / "shots" / "shot.usda")
    choose = profile_chooser(load_settings(start=str(show / "shots")))
    assert choose(shot) == ("karma", f"{studio}: per-path-profiles.** = karma")


@pytest.fixture(autouse=True)
def _home():
    saved = os.environ.get("HOME")
    yield
    if saved is None:
        os.environ.pop("HOME", None)
    else:
        os.environ["HOME"] = saved


@pytest.mark.parametrize(
    ("studio", "says"),
    [
        (None, "'extend': no such file: "),
        ('extend = "../show/.usdrender-lint.toml"\n', "'extend' makes a cycle: "),
        ("fail-on = 3\n", "studio.toml:1: 'fail-on' must be one of"),
        ("extend = 3\n", "studio.toml:1: 'extend' must be the path of a configuration file"),
        ("[", "studio.toml:1:2: invalid TOML"),
    ],
    ids=["missing", "cycle", "bad-value", "bad-extend", "bad-toml"],
)
def test_an_error_names_the_file_that_holds_it(show: Path, studio: str | None, says: str) -> None:
    target = show.parent / "studio" / "studio.toml"
    if studio is None:
        target.unlink()
    else:
        target.write_text(studio)
    with pytest.raises(ConfigError) as raised:
        load_settings(start=str(show / "shots"))
    assert says in str(raised.value)
    result = CliRunner().invoke(cli, ["check", "--no-cache", str(show / "shots")])
    assert result.exit_code == 2
    assert says in result.stderr and len(result.stderr.splitlines()) == 1


@pytest.mark.parametrize(
    ("extend", "says"),
    [
        (
            "../studio",
            "show/.usdrender-lint.toml:1: 'extend': a folder, not a configuration file: ",
        ),
        ("../pyproject.toml", "pyproject.toml: no [tool.usdrender-lint] table (which "),
    ],
    ids=["folder", "pyproject-without-table"],
)
def test_an_extended_file_that_is_no_configuration_names_the_extending_file(
    show: Path, extend: str, says: str
) -> None:
    (show.parent / "pyproject.toml").write_text('[project]\nname = "x"\n')
    (show / ".usdrender-lint.toml").write_text(f'extend = "{extend}"\n')
    result = CliRunner().invoke(cli, ["check", "--no-cache", str(show / "shots")])
    assert result.exit_code == 2
    assert says in result.stderr and len(result.stderr.splitlines()) == 1
    assert str(show / ".usdrender-lint.toml") in result.stderr


def test_a_bad_rule_in_the_extended_file_is_named_there(show: Path) -> None:
    (show.parent / "studio" / "studio.toml").write_text('select = ["XX999"]\n')
    result = CliRunner().invoke(cli, ["check", "--no-cache", str(show / "shots")])
    assert result.exit_code == 2
    assert "studio.toml:1: select" in result.stderr, result.stderr


@pytest.mark.parametrize(
    ("entry", "says"),
    [
        ('severity.XX999 = "info"', "severity.XX999: no rule"),
        ("rules.XX999.x = 1", "rules.XX999: no rule"),
        ('per-path-ignores."old/*" = ["XX999"]', "per-path-ignores.old/*: 'XX999'"),
        ('per-path-profiles."old/*" = "nope"', "per-path-profiles.old/*: unknown profile"),
        ('unfixable = ["XX999"]', "unfixable: 'XX999'"),
    ],
    ids=["severity", "rules", "per-path-ignores", "per-path-profiles", "unfixable"],
)
def test_a_bad_entry_of_a_merged_table_or_list_is_named_in_its_file(
    show: Path, entry: str, says: str
) -> None:
    """The show sets the same table (or list) too: the error still names the
    studio's file, which holds the bad entry, not the show's."""
    studio = show.parent / "studio" / "studio.toml"
    studio.write_text(entry)
    (show / ".usdrender-lint.toml").write_text(
        'extend = "../studio/studio.toml"\nunfixable = ["CA006"]\n'
        '[severity]\nSE015 = "info"\n[rules.SE001]\nrequire-authored = true\n'
        '[per-path-ignores]\n"wip/*" = ["SE"]\n[per-path-profiles]\n"wip/*" = "arnold"\n'
    )
    result = CliRunner().invoke(cli, ["check", "--no-cache", str(show / "shots")])
    assert result.exit_code == 2
    assert f"{studio}:1: {says}" in result.stderr, result.stderr  # and its line
    # and an inline --config's entry is named as the inline setting, not the file
    studio.write_text("")
    args = ["check", "--no-cache", "--config", entry, str(show / "shots")]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 2
    assert f"--config '{entry}': {says}" in result.stderr, result.stderr


def test_the_server_reads_the_settings_again_when_the_extended_file_changes(show: Path) -> None:
    shot = show / "shots" / "shot.usda"
    documents = Documents()
    documents.update({str(shot): shot.read_text()})
    before = {f.code: f.severity.value for f in documents.lint(str(shot)).findings}
    assert before["SE003"] == "warning"
    studio = show.parent / "studio" / "studio.toml"
    studio.write_text(STUDIO.replace('SE003 = "warning"', 'SE003 = "info"'))
    os.utime(studio, ns=(1, 1))  # a new modification time, whatever the clock's resolution
    after = {f.code: f.severity.value for f in documents.lint(str(shot)).findings}
    assert after["SE003"] == "info"


def test_unfixable_adds_to_the_extended_files(show: Path) -> None:
    """As ruff's: a show cannot make fixable again what the studio made unfixable."""
    studio = show.parent / "studio" / "studio.toml"
    studio.write_text('unfixable = ["CA004"]\n' + STUDIO)
    (show / ".usdrender-lint.toml").write_text('unfixable = ["SE003"]\n' + SHOW)
    assert read_config_file(show / ".usdrender-lint.toml").unfixable == ("CA004", "SE003")
