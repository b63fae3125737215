"""Configuration through the command line: every key, precedence, discovery, errors."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.config import Settings, load_settings
from usdrender_lint.running.path_ignores import matches_path

# SE003 (error) on a bad window; SE001's require-authored option reports the
# unauthored resolution; CA001 (error) for the product without a camera.
SHOT = """#usda 1.0

def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform float4 dataWindowNDC = (0.8, 0, 0.2, 1)
        rel products = </Render/Beauty>
    }

    def RenderProduct "Beauty"
    {
        token productName = "beauty.exr"
    }
}
"""


@pytest.fixture
def project(tmp_path: Path) -> Path:
    (tmp_path / "shots").mkdir()
    (tmp_path / "shots" / "shot.usda").write_text(SHOT, encoding="utf-8")
    return tmp_path


def _write(folder: Path, text: str, name: str = ".usdrender-lint.toml") -> Path:
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


def check(project: Path, *args: str):
    """Run ``check --format json`` on the shot (serially: fast and in-process)."""
    return CliRunner().invoke(
        cli,
        [
            "check",
            "--format",
            "json",
            "--jobs",
            "1",
            "--timeout",
            "0",
            *args,
            str(project / "shots" / "shot.usda"),
        ],
    )


def findings(result) -> dict[str, str]:
    """code -> severity of the findings in a JSON report."""
    assert result.exit_code in (0, 1), result.output
    document = json.loads(result.stdout)
    return {f["code"]: f["severity"] for file in document["files"] for f in file["findings"]}


def error_line(result) -> str:
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert "Traceback" not in result.output
    return lines[0]


# -- every key --------------------------------------------------------------------


def test_defaults_run_every_rule(project) -> None:
    found = findings(check(project))
    assert {"SE003", "CA001"} <= set(found)


def test_select(project) -> None:
    _write(project, 'select = ["SE003"]\n')
    assert set(findings(check(project))) == {"SE003"}


def test_ignore(project) -> None:
    _write(project, 'ignore = ["SE003", "camera-unset"]\n')
    found = findings(check(project))
    assert "SE003" not in found and "CA001" not in found and found


def test_extend_select(project) -> None:
    _write(project, 'select = ["SE003"]\nextend-select = ["CA"]\n')
    assert set(findings(check(project))) == {"SE003", "CA001"}


@pytest.mark.parametrize(("fail_on", "code"), [("never", 0), ("error", 1), ("info", 1)])
def test_fail_on(project, fail_on, code) -> None:
    _write(project, f'fail-on = "{fail_on}"\n')
    assert check(project).exit_code == code


def test_fail_on_warning_counts_overridden_severities(project) -> None:
    _write(project, 'select = ["SE003"]\nfail-on = "error"\n[severity]\nSE003 = "warning"\n')
    result = check(project)
    assert findings(result) == {"SE003": "warning"}
    assert result.exit_code == 0


def test_severity_override_by_name(project) -> None:
    _write(project, 'select = ["SE003"]\n[severity]\ndata-window-malformed = "info"\n')
    assert findings(check(project)) == {"SE003": "info"}


def test_per_path_ignores(project) -> None:
    _write(project, '[per-path-ignores]\n"shots/*.usda" = ["SE003", "CA"]\n"other/*" = ["ALL"]\n')
    found = findings(check(project))
    assert "SE003" not in found and "CA001" not in found and found


def test_per_path_ignores_only_match_their_files(project) -> None:
    _write(project, '[per-path-ignores]\n"other/*.usda" = ["SE003"]\n')
    assert "SE003" in findings(check(project))


@pytest.mark.parametrize("glob", ["{shots,other}/*.usda", "{other,shots/}/*.usda", "*.{usdc,usda}"])
def test_per_path_ignores_take_alternatives_in_braces(project, glob) -> None:
    """As ruff's per-file-ignores ("{benchmark,scripts}/*.py" in its settings
    reference): a brace group matches any of its alternatives."""
    _write(project, f'[per-path-ignores]\n"{glob}" = ["SE003"]\n')
    found = findings(check(project))
    assert "SE003" not in found and found
    _write(project, '[per-path-ignores]\n"{other,more}/*.usda" = ["SE003"]\n')
    assert "SE003" in findings(check(project))


def test_a_negated_per_path_glob_matches_the_other_files(project) -> None:
    """As ruff's per-file-ignores: "An initial '!' negates the file pattern"."""
    _write(project, '[per-path-ignores]\n"!other/*.usda" = ["SE003"]\n')
    found = findings(check(project))
    assert "SE003" not in found and found
    _write(project, '[per-path-ignores]\n"!shots/*.usda" = ["SE003"]\n')
    assert "SE003" in findings(check(project))
    # per-path-profiles read their globs alike
    shot = str(project / "shots" / "shot.usda")
    assert matches_path("!other/*", shot, project) and not matches_path("!shots/*", shot, project)


@pytest.mark.parametrize(
    "glob", ["{project}/shots/shot.usda", "{project}/shots/*.usda", "../shots/*.usda"]
)
def test_per_path_ignores_take_absolute_and_parent_globs(project, glob) -> None:
    # The config sits in a subfolder: its globs name the shot from there.
    (project / "cfg").mkdir()
    pattern = glob.format(project=project.as_posix())
    _write(project / "cfg", f'[per-path-ignores]\n"{pattern}" = ["SE003"]\n')
    found = findings(check(project, "--config", str(project / "cfg" / ".usdrender-lint.toml")))
    assert "SE003" not in found and found


def test_per_path_ignores_hold_for_a_file_named_through_a_linked_folder(project) -> None:
    _write(project, '[per-path-ignores]\n"shots/*.usda" = ["SE003"]\n')
    link = project.parent / f"{project.name}-link"
    link.symlink_to(project, target_is_directory=True)
    assert "SE003" not in findings(check(link))


def test_a_linked_config_file_reads_its_globs_from_the_folder_it_is_found_in(
    project, monkeypatch
) -> None:
    """A show's configuration that links to a studio-wide file: its globs,
    patterns and cache are the show's, not the studio folder's."""
    studio = project.parent / f"{project.name}-studio"
    studio.mkdir()
    _write(studio, '[per-path-ignores]\n"shots/*.usda" = ["SE003"]\n', "std.toml")
    (project / ".usdrender-lint.toml").symlink_to(studio / "std.toml")
    monkeypatch.delenv("USDRENDER_LINT_NO_CACHE")
    args = ["check", "--format", "json", "--jobs", "1", str(project / "shots")]
    result = CliRunner().invoke(cli, args)
    assert "SE003" not in findings(result)
    assert (project / ".usdrender_lint_cache").is_dir()
    assert not (studio / ".usdrender_lint_cache").exists()


def test_cache_dir_expands_the_home_folder_and_variables(project, monkeypatch) -> None:
    """As ruff's cache-dir ("~/.cache/ruff" in its settings reference): never a
    folder named '~' or '$VAR' in the project."""
    home = project.parent / f"{project.name}-home"
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.setenv("SHOW_CACHE", str(home / "show"))
    monkeypatch.delenv("USDRENDER_LINT_NO_CACHE")
    args = ["check", "--format", "json", "--jobs", "1", str(project / "shots")]
    for value, made in [("~/ul-cache", home / "ul-cache"), ("${SHOW_CACHE}/c", home / "show/c")]:
        _write(project, f'cache-dir = "{value}"\n')
        assert findings(CliRunner().invoke(cli, args))
        assert made.is_dir(), value
    assert not (project / "~").exists() and not (project / "${SHOW_CACHE}").exists()
    _write(project, 'cache-dir = "$NOT_SET_ANYWHERE/c"\n')
    line = error_line(CliRunner().invoke(cli, args))
    assert "'cache-dir': environment variable NOT_SET_ANYWHERE is not set" in line


def test_per_path_ignores_glob_of_a_hidden_folder_names_it(project) -> None:
    (project / "shots" / ".wip").mkdir()
    (project / "shots" / ".wip" / "shot.usda").write_text(SHOT, encoding="utf-8")
    _write(project / "shots", '[per-path-ignores]\n".wip/*.usda" = ["SE003"]\n"wip/*" = ["CA"]\n')
    result = CliRunner().invoke(
        cli, ["check", "--format", "json", "--no-cache", str(project / "shots" / ".wip")]
    )
    found = findings(result)
    assert "SE003" not in found and "CA001" in found


def test_rule_options(project) -> None:
    assert "SE001" not in findings(check(project))
    _write(project, "[rules.resolution-non-positive]\nrequire-authored = true\n")
    assert "SE001" in findings(check(project))
    _write(project, "[rules.SE001]\nrequire_authored = true\n")
    assert "SE001" in findings(check(project))


def test_roots_and_time_sample_cap_are_read(project) -> None:
    path = _write(project, 'roots = ["shots/*.usda"]\ntime-sample-cap = 5\n')
    settings = load_settings(str(path))
    assert settings.roots == ("shots/*.usda",)
    assert settings.time_sample_cap == 5


# -- precedence and discovery -----------------------------------------------------


def test_flags_win_over_the_file(project) -> None:
    _write(project, 'select = ["SE003"]\nfail-on = "never"\n')
    result = check(project, "--select", "CA001", "--fail-on", "error")
    assert set(findings(result)) == {"CA001"}
    assert result.exit_code == 1


def test_extend_flags_add_to_the_files_lists(project) -> None:
    """As ruff's: a rule or pattern added on the command line keeps the file's."""
    _write(project, 'select = ["PR"]\nextend-select = ["SE003"]\n')
    assert set(findings(check(project, "--extend-select", "CA001"))) == {"PR004", "SE003", "CA001"}
    # --select starts the selection over, the file's extend-select with it.
    assert set(findings(check(project, "--select", "CA001"))) == {"CA001"}
    (project / "old").mkdir()
    (project / "old" / "shot.usda").write_text(SHOT, encoding="utf-8")
    _write(project, 'extend-exclude = ["old/"]\n')
    shown = CliRunner().invoke(
        cli, ["check", "--show-files", "--extend-exclude", "tmp/", str(project)]
    )
    assert shown.stdout.splitlines() == [str(project / "shots" / "shot.usda")]


def test_the_selection_flags_are_laid_over_the_files_selection(project) -> None:
    """As ruff layers them: ``--select`` runs what the file ignores (a gate of
    one family must not pass in silence), ``--ignore`` adds to the file's
    ignores, ``--extend-select`` brings back one of them."""
    _write(project, 'ignore = ["CA", "SE003", "ST003"]\n')
    assert set(findings(check(project))) == {"PR004"}
    assert set(findings(check(project, "--select", "CA"))) == {"CA001"}
    assert set(findings(check(project, "--ignore", "PR004"))) == set()
    assert set(findings(check(project, "--extend-select", "CA001"))) == {"PR004", "CA001"}
    shown = CliRunner().invoke(cli, ["check", "--show-settings", "--ignore", "PR004", str(project)])
    assert (
        f'#   ignore = ["CA", "SE003", "ST003"]  ({project / ".usdrender-lint.toml"}: ignore)'
        in shown.stdout
    )
    assert '#   ignore = ["PR004"]  (--ignore)' in shown.stdout


def test_pyproject_table_is_found_from_the_linted_file(project) -> None:
    _write(
        project,
        '[project]\nname = "x"\n[tool.usdrender-lint]\nselect = ["SE003"]\n',
        "pyproject.toml",
    )
    assert set(findings(check(project))) == {"SE003"}


def test_dedicated_file_wins_and_pyproject_without_table_is_skipped(project) -> None:
    _write(project, 'select = ["CA001"]\n')
    _write(project / "shots", '[project]\nname = "x"\n', "pyproject.toml")
    assert set(findings(check(project))) == {"CA001"}


def test_a_plain_usdrender_lint_toml_is_read_between_the_dotted_one_and_pyproject(
    project,
) -> None:
    shots = project / "shots"
    _write(shots, '[tool.usdrender-lint]\nselect = ["SE003"]\n', "pyproject.toml")
    _write(shots, 'select = ["CA001"]\n', "usdrender-lint.toml")
    assert set(findings(check(project))) == {"CA001"}
    _write(shots, 'select = ["CA001", "SE003"]\n')
    assert set(findings(check(project))) == {"CA001", "SE003"}
    (shots / ".usdrender-lint.toml").unlink()
    (shots / "usdrender-lint.toml").unlink()
    assert set(findings(check(project))) == {"SE003"}


def test_config_flag_and_isolated(project, tmp_path_factory) -> None:
    _write(project, 'select = ["SE003"]\n')
    elsewhere = _write(tmp_path_factory.mktemp("cfg"), 'select = ["CA001"]\n')
    assert set(findings(check(project, "--config", str(elsewhere)))) == {"CA001"}
    assert {"SE003", "CA001"} <= set(findings(check(project, "--isolated")))
    line = error_line(check(project, "--isolated", "--config", str(elsewhere)))
    assert "--config and --isolated" in line


def test_settings_record_flags() -> None:
    merged = Settings(source="a.toml").merged(select=("SE",), ignore=None)
    assert merged.where("select") == "--select"
    assert merged.where("ignore") == "a.toml: ignore"


# -- errors: one line naming the key and the file, exit 2 ------------------------

ERRORS = [
    ("selct = []\n", "unknown key 'selct'"),
    ('select = "SE003"\nignore = [1]\n', "'ignore' must be a list of strings"),
    ('select = ["NOPE"]\n', "select: 'NOPE' matches no rule"),
    ('extend-select = ["no-such-rule"]\n', "extend-select: 'no-such-rule' matches no rule"),
    ('fail-on = "fatal"\n', "'fail-on' must be one of error, warning, info, never"),
    ('severity = "error"\n', "'severity' must be a table"),
    ('[severity]\nSE003 = "fatal"\n', "'severity.SE003' must be one of error, warning, info"),
    ('[severity]\nXX001 = "info"\n', "severity.XX001: no rule has this code or name"),
    ('[per-path-ignores]\n"*.usda" = 3\n', "'per-path-ignores.*.usda' must be a list of strings"),
    ('[per-path-ignores]\n"*.usda" = ["XX"]\n', "per-path-ignores.*.usda: 'XX' matches no rule"),
    ("[rules]\nSE001 = 1\n", "'rules.SE001' must be a table"),
    ("[rules.no-such-rule]\nx = 1\n", "rules.no-such-rule: no rule has this code or name"),
    ("[rules.SE001]\nstrict = true\n", "rules.SE001: unknown option 'strict'"),
    ('[rules.SE001]\nrequire-authored = "yes"\n', "must be true or false, got 'yes'"),
    ("[rules.SE003]\nx = 1\n", "rules.SE003: this rule takes no options"),
    ("time-sample-cap = 0\n", "'time-sample-cap' must be a positive integer"),
    ("roots = [1]\n", "'roots' must be a list of strings"),
    # A blank selector ran no rule (select) or silenced every rule (a per-path-ignores entry).
    ('select = [""]\n', "'select' has a blank entry, which names no rule"),
    ('ignore = ["SE001", " "]\n', "'ignore' has a blank entry, which names no rule"),
    ('unfixable = [","]\n', "'unfixable' has a blank entry, which names no rule"),
    ('[per-path-ignores]\n"*.usda" = [""]\n', "per-path-ignores.*.usda: '' matches no rule"),
    ("select = [\n", "invalid TOML"),
    # A pyproject's table copied whole into a .usdrender-lint.toml.
    (
        '[tool.usdrender-lint]\nselect = ["SE003"]\n',
        "unknown key 'tool' (this file holds the keys at the top level: drop the "
        "[tool.usdrender-lint] header",
    ),
    # ruff's [lint] table, which has no counterpart here.
    ('[lint]\nselect = ["SE003"]\n', "unknown key 'lint' (ruff's [lint] table: here its keys"),
]


@pytest.mark.parametrize(("text", "expected"), ERRORS, ids=[e[1][:40] for e in ERRORS])
def test_bad_config_is_one_line_naming_key_and_file(project, text, expected) -> None:
    path = _write(project, text)
    line = error_line(check(project))
    assert line.startswith("usdrender-lint: error: ")
    assert str(path) in line and expected in line


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('fail-on = "error"\n\nselct = []\n', ":3: unknown key 'selct'"),
        ("# a comment\ntime-sample-cap = 0\n", ":2: 'time-sample-cap' must be"),
        ('[severity]\nSE001 = "info"\nSE003 = "loud"\n', ":3: 'severity.SE003' must be"),
        ('[per-path-ignores]\n"x.usda" = ["SE"]\n"a/*.usda" = 3\n', ":3: 'per-path-ignores.a/*"),
        # A glob that names no file ignores nothing; '!' before one, everything.
        ('[per-path-ignores]\n"x.usda" = ["SE"]\n"" = ["SE"]\n', ":3: 'per-path-ignores.' is an"),
        ('[per-path-ignores]\n"x.usda" = ["SE"]\n" " = ["SE"]\n', ":3: 'per-path-ignores. ' is an"),
        ('[per-path-ignores]\n"x.usda" = ["SE"]\n"!" = ["SE"]\n', ":3: 'per-path-ignores.!' negat"),
        ('per-path-ignores = { "{,}" = ["SE"] }\n', ":1: 'per-path-ignores.{,}' is an empty glob"),
        # A folder, as .gitignore writes one: these globs match files (ruff's too).
        (
            '[per-path-ignores]\n"x.usda" = ["SE"]\n"shots/" = ["SE"]\n',
            ":3: 'per-path-ignores.shots/",
        ),
        ('[per-path-profiles]\n"!old/ " = "karma"\n', ":2: 'per-path-profiles.!old/ ' names a"),
        ('[per-path-profiles]\n"*.usda" = "karma"\n" " = "arnold"\n', ":3: 'per-path-profiles. "),
        ('x = """\nselct = 1\n"""\n', ":1: unknown key 'x'"),
        ('profile = "auto"\nextend = "missing.toml"\n', ":2: 'extend': no such file"),
        # Found once the rules are known (a code, a name, an option): they had no line.
        ('fail-on = "error"\nselect = ["NOPE"]\n', ":2: select: 'NOPE' matches no rule"),
        ('[severity]\nSE001 = "info"\nXX001 = "info"\n', ":3: severity.XX001: no rule"),
        (
            '[per-path-ignores]\n"x.usda" = ["SE"]\n"*.usda" = ["XX"]\n',
            ":3: per-path-ignores.*.usda",
        ),
        ("[rules.SE001]\n\nstrict = true\n", ":3: rules.SE001: unknown option 'strict'"),
        ("[rules.SE001]\nrequire-authored = 1\n", ":2: rules.SE001.require-authored: must be"),
        ('time-sample-cap = 5\nprofile = "Karma"\n', ":2: profile: unknown profile 'Karma'"),
    ],
)
def test_a_bad_key_names_its_line(project, text, expected) -> None:
    """As a TOML syntax error does (file:line:col), and as ruff's errors do."""
    path = _write(project, text)
    assert f"{path}{expected}" in error_line(check(project))


@pytest.mark.parametrize(
    ("key", "meant"),
    [
        ("per-file-ignores", "per-path-ignores"),
        ("extend-per-file-ignores", "per-path-ignores"),
        ("extend-ignore", "ignore"),
        ("rule-options", "rules"),
        ("failon", "fail-on"),
    ],
)
def test_an_unknown_key_ruff_or_a_typo_spells_names_ours(project, key, meant) -> None:
    _write(project, f"[{key}]\n")
    assert f"unknown key '{key}' (did you mean '{meant}'?)" in error_line(check(project))
    inline = CliRunner().invoke(cli, ["check", "--config", f"{key}.x = 1", str(project)])
    assert f"unknown key '{key}' (did you mean '{meant}'?)" in error_line(inline)


def test_a_pyproject_key_names_its_line_in_the_pyproject(project) -> None:
    path = _write(
        project,
        '[project]\nname = "x"\n\n[tool.usdrender-lint]\nfail-on = "error"\n'
        "[tool.usdrender-lint.rules]\nx = 3\n",
        "pyproject.toml",
    )
    assert f"{path}:7: 'tool.usdrender-lint.rules.x' must be" in error_line(check(project))


def test_pyproject_errors_name_the_qualified_key(project) -> None:
    path = _write(project, "[tool.usdrender-lint]\nfail-on = 3\n", "pyproject.toml")
    line = error_line(check(project))
    assert str(path) in line and "'tool.usdrender-lint.fail-on' must be one of" in line


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('[project]\nname = "x"\n', "no [tool.usdrender-lint] table"),
        ("[tool]\nusdrender-lint = 3\n", "'tool.usdrender-lint' must be a table"),
    ],
)
def test_config_flag_pyproject_without_a_table(project, text, expected) -> None:
    path = _write(project, text, "pyproject.toml")
    line = error_line(check(project, "--config", str(path)))
    assert str(path) in line and expected in line


def test_missing_config_file(project) -> None:
    line = error_line(check(project, "--config", str(project / "nope.toml")))
    assert "nope.toml: cannot read config file" in line


def test_bad_flag_selector_names_the_flag(project) -> None:
    line = error_line(check(project, "--ignore", "XX9"))
    assert "--ignore: 'XX9' matches no rule" in line


def test_the_configuration_guides_example_is_valid(tmp_path) -> None:
    from usdrender_lint.registry import build_registry
    from usdrender_lint.running.pipeline import make_linter

    guide = Path(__file__).parents[2] / "docs" / "guides" / "configuration.md"
    section = guide.read_text(encoding="utf-8").split("\n## ", 1)[0]
    example = section.split("```toml\n", 1)[1].split("```", 1)[0]
    settings = load_settings(str(_write(tmp_path, example, "pyproject.toml")))
    assert settings.fail_on == "warning" and settings.per_path_ignores
    make_linter(settings, build_registry())  # every code, name and option exists


# -- hostile config files (issue 31) ------------------------------------------------


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom"])
def test_a_config_that_is_a_device_is_refused(project, device) -> None:
    """/dev/zero was read until the kernel killed the process; /dev/urandom never ended."""
    if not Path(device).exists():
        pytest.skip(f"no {device}")
    line = error_line(check(project, "--config", device))
    assert line == f"usdrender-lint: error: {device}: cannot read config file: not a regular file"


def test_a_config_larger_than_the_bound_is_refused(project) -> None:
    path = _write(project, "# " + "x" * (4 * 1024 * 1024) + "\n")
    line = error_line(check(project, "--config", str(path)))
    assert line.endswith(": cannot read config file: larger than 4 MiB")


def _fifo(path: Path) -> None:
    import os

    os.mkfifo(path)


@pytest.mark.parametrize("name", [".usdrender-lint.toml", "pyproject.toml"])
@pytest.mark.parametrize(
    ("kind", "make", "expected"),
    [
        ("dangling", lambda p: p.symlink_to(p.parent / "gone.toml"), "a symbolic link to nothing"),
        ("loop", lambda p: p.symlink_to(p), "Too many levels of symbolic links"),
        ("fifo", _fifo, "not a regular file"),
        ("folder", lambda p: p.mkdir(), "a folder"),
    ],
)
def test_a_config_name_that_is_not_a_regular_file_is_an_error(
    project, name, kind, make, expected
) -> None:
    """Such a file was skipped silently and the parent folder's config used."""
    _write(project, "[tool.usdrender-lint]\nselect = ['CA']\n", "pyproject.toml")
    make(project / "shots" / name)
    line = error_line(check(project))
    assert line == (
        f"usdrender-lint: error: {project / 'shots' / name}: cannot read config file: {expected}"
    ), kind


def test_a_deeply_nested_config_is_one_line(project) -> None:
    path = _write(project, "a = " + "[" * 100_000 + "]" * 100_000 + "\n")
    line = error_line(check(project, "--config", str(path)))
    assert (
        line == f"usdrender-lint: error: {path}: invalid TOML: arrays or tables nested too deeply"
    )


def test_a_byte_order_mark_is_read_past(project: Path) -> None:
    """Windows editors save UTF-8 with a byte order mark, which TOML has no
    statement for: the file is read as its text."""
    (project / ".usdrender-lint.toml").write_bytes(b'\xef\xbb\xbfselect = ["SE003"]\n')
    assert findings(check(project)) == {"SE003": "error"}
    (project / ".usdrender-lint.toml").write_bytes(b'\xef\xbb\xbfselect = ["SE003"\n')
    assert error_line(check(project)).endswith(
        ".usdrender-lint.toml:2:1: invalid TOML: " + ("Unclosed array")
    ), "a position after the mark is still the text's"


@pytest.mark.parametrize("table", ["usdrender_lint", "UsdRender-Lint", "usdrenderlint"])
def test_a_misspelt_table_is_an_error_not_the_defaults(project: Path, table: str) -> None:
    _write(project, f'[tool.{table}]\nselect = ["SE003"]\n', name="pyproject.toml")
    assert error_line(check(project)).endswith(
        f"pyproject.toml: [tool.{table}] is not read: the table is [tool.usdrender-lint]"
    )


def test_ruffs_lint_table_in_a_pyproject_says_where_its_keys_go(project) -> None:
    _write(project, '[tool.usdrender-lint.lint]\nselect = ["SE003"]\n', "pyproject.toml")
    line = error_line(check(project))
    assert "unknown key 'tool.usdrender-lint.lint' (ruff's [lint] table: here its keys are " in line
    assert "in [tool.usdrender-lint] itself)" in line


def test_set_and_table_options_are_checked_against_their_hints() -> None:
    # A set or mapping option took any value: a TOML array stayed a list (a
    # frozenset[str] option's `|` then failed inside the rule), a table's
    # values were never checked.
    from usdrender_lint.api import record
    from usdrender_lint.config import ConfigError, build_options

    @record(frozen=True)
    class Options:
        names: frozenset[str] = frozenset()
        sizes: dict[str, int] | None = None

    built = build_options(Options, {"names": ["a", "b"], "sizes": {"hd": 1080}}, "rules.x")
    assert built == Options(names=frozenset({"a", "b"}), sizes={"hd": 1080})
    for values, said in (
        ({"names": [1]}, "rules.x.names: must be str, got 1"),
        ({"names": "a"}, "rules.x.names: must be a list, got 'a'"),
        ({"sizes": {"hd": "x"}}, "rules.x.sizes"),
        ({"sizes": [1]}, "rules.x.sizes"),
    ):
        with pytest.raises(ConfigError, match=re.escape(said)):
            build_options(Options, values, "rules.x")


def test_options_hints_that_cannot_be_read_are_a_config_error_naming_the_rule() -> None:
    # It was "internal error: NameError: name 'Undefined' is not defined", naming no rule.
    from usdrender_lint.api import record
    from usdrender_lint.config import ConfigError, build_options

    @record(frozen=True)
    class Options:
        path: Undefined | None = None  # type: ignore[name-defined]  # noqa: F821

    with pytest.raises(ConfigError, match=r"rules\.opt-rule: the rule's Options type hints"):
        build_options(Options, {"path": "a"}, "rules.opt-rule")


@pytest.mark.parametrize("flag", ["--select", "--ignore", "--extend-select"])
@pytest.mark.parametrize("value", ["", " ", ","])
def test_a_blank_selector_flag_is_a_usage_error(project, flag: str, value: str) -> None:
    """``--select ""`` (an unset shell variable) ran no rule and passed, exit 0."""
    result = check(project, flag, value)
    assert result.exit_code == 2, result.output
    assert f"Invalid value for '{flag}': a blank value names no rule" in result.stderr


def test_a_folder_glob_says_the_glob_that_matches_its_files(project) -> None:
    _write(project, '[per-path-ignores]\n"shots/" = ["SE003"]\n')
    assert error_line(check(project)).endswith(
        "'per-path-ignores.shots/' names a folder, and these globs match files, so it matches "
        'no file: "shots/**" matches every file below it'
    )
    _write(project, '[per-path-ignores]\n"!shots/" = ["SE003"]\n')
    assert error_line(check(project)).endswith(
        'so it matches every file: "!shots/**" matches every file outside it'
    )
    _write(project, '[per-path-ignores]\n"shots/**" = ["SE003"]\n')
    assert "SE003" not in findings(check(project))
