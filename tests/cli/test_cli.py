"""The command line: exit codes, both formats, rules and explain."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli

pytestmark = pytest.mark.heavy(seconds=31)

REPO = Path(__file__).parents[2]
EXAMPLES = REPO / "examples"
CLEAN = EXAMPLES / "clean_shot" / "shot.usda"
BROKEN = EXAMPLES / "broken_shot" / "shot.usda"
WIP = EXAMPLES / "broken_shot" / "lighting_wip.usda"

HEADLINE = {"ST001", "CA003", "CA004", "SE003", "SE007", "PR004"}


def run(*args: str):
    return CliRunner().invoke(cli, ["check", "--isolated", *args])


def findings_of(output: str) -> list[dict]:
    document = json.loads(output)
    return [f for file in document["files"] for f in file["findings"]]


def test_clean_file_exits_0() -> None:
    result = run(str(CLEAN))
    assert result.exit_code == 0, result.output
    assert "0 errors, 0 warnings" in result.output


def test_examples_directory_reports_every_headline_check() -> None:
    result = run("--format", "json", str(EXAMPLES))
    assert result.exit_code == 1
    findings = findings_of(result.output)
    assert {f["code"] for f in findings} >= HEADLINE
    clean = [
        f for f in findings if "clean_shot" in f["file"] and f["severity"] in ("error", "warning")
    ]
    assert clean == []


def test_check_without_paths_lints_the_working_directory(tmp_path: Path) -> None:
    """As ruff checks the current directory (and clean cleans it): the same
    report as ``check .``, folders walked, the configuration found there."""
    from cli_support import BROKEN, invoke_in

    (tmp_path / "shots").mkdir()
    (tmp_path / "shots" / "shot.usda").write_text(BROKEN.read_text())
    (tmp_path / "hidden_wip.usda").write_text(BROKEN.read_text())
    (tmp_path / ".usdrender-lint.toml").write_text('extend-exclude = ["*_wip.usda"]\n')
    bare = invoke_in(tmp_path, "check", "--no-cache", "--format", "json")
    dot = invoke_in(tmp_path, "check", "--no-cache", "--format", "json", ".")
    assert (bare.exit_code, bare.stderr) == (1, ""), bare.output
    assert bare.stdout == dot.stdout
    assert [f["file"] for f in json.loads(bare.stdout)["files"]] == ["shots/shot.usda"]


def test_every_format_names_the_files_of_a_walk_as_given_alone(tmp_path: Path) -> None:
    """As ruff names them: ``check .`` and ``check ./shots//`` report ``shots/shot.usda``,
    in every format, as ``check shots/shot.usda`` does; an absolute path stays absolute."""
    from cli_support import BROKEN, invoke_in

    from usdrender_lint.formatters import available_formatters

    (tmp_path / "shots").mkdir()
    shot = tmp_path / "shots" / "shot.usda"
    shot.write_text(BROKEN.read_text())
    for report_format in sorted(available_formatters()):
        given = ["check", "--isolated", "--no-cache", "--format", report_format]
        named = invoke_in(tmp_path, *given, "shots/shot.usda")
        for path in (".", "./shots//", "./shots/./shot.usda"):
            walked = invoke_in(tmp_path, *given, path)
            assert walked.exit_code == 1, walked.output
            assert walked.stdout == named.stdout, (report_format, path)
    absolute = invoke_in(tmp_path, "check", "--isolated", "--format", "json", str(shot))
    assert json.loads(absolute.stdout)["files"][0]["file"] == str(shot)


def test_the_hooks_files_named_like_options_are_paths(tmp_path: Path) -> None:
    """``check --pre-commit ARGS FILES`` (the pre-commit hooks' entry, the user's
    args, the staged files): a staged ``-x.usda`` is a path, the args options."""
    from cli_support import BROKEN, invoke_in

    (tmp_path / "-x.usda").write_text(BROKEN.read_text())
    (tmp_path / "--fix.usda").write_text(BROKEN.read_text())
    args = ["check", "--isolated", "--no-cache", "--format", "json", "--pre-commit"]
    done = invoke_in(tmp_path, *args, "--select", "SE003", "-x.usda", "--fix.usda")
    assert done.exit_code == 1, done.output
    files = json.loads(done.stdout)["files"]
    assert [f["file"] for f in files] == ["-x.usda", "--fix.usda"]
    assert {x["code"] for f in files for x in f["findings"]} == {"SE003"}
    assert (tmp_path / "--fix.usda").read_text() == BROKEN.read_text()
    # Without the hooks' flag, a name that starts with '-' is an option, as for any command.
    alone = invoke_in(tmp_path, "check", "--isolated", "-x.usda")
    assert alone.exit_code == 2 and "No such option" in alone.output


def test_missing_path_exits_2_and_still_lints_the_others(tmp_path: Path) -> None:
    missing = tmp_path / "nope.usda"
    result = run("--format", "json", str(missing), str(BROKEN))
    assert result.exit_code == 2
    files = {f["file"]: f for f in json.loads(result.stdout)["files"]}
    assert files[str(missing)]["status"] == "error"
    assert "no such file" in files[str(missing)]["error"]
    assert files[str(BROKEN)]["status"] == "linted"
    assert files[str(BROKEN)]["findings"]
    assert f"usdrender-lint: error: {missing}: no such file" in result.stderr


def test_unparsable_file_is_an_st001_finding_not_a_crash() -> None:
    result = run("--format", "json", str(WIP), str(CLEAN))
    assert result.exit_code == 1
    findings = findings_of(result.output)
    assert [f["code"] for f in findings] == ["ST001"]
    assert findings[0]["line"] == 9
    assert "Expected }" in findings[0]["message"]


@pytest.mark.parametrize(
    ("fail_on", "expected"), [("error", 0), ("warning", 1), ("info", 1), ("never", 0)]
)
def test_fail_on_threshold(fail_on: str, expected: int) -> None:
    # Only SE007 (a warning) is selected.
    result = run("--select", "SE007", "--fail-on", fail_on, str(BROKEN))
    assert result.exit_code == expected, result.output


def test_fail_on_never_still_reports() -> None:
    result = run("--fail-on", "never", str(BROKEN))
    assert result.exit_code == 0
    assert "CA004" in result.output


def test_select_and_ignore_by_prefix_code_and_name() -> None:
    result = run(
        "--format", "json", "--select", "CA", "--ignore", "camera-target-missing", str(BROKEN)
    )
    assert {f["code"] for f in findings_of(result.output)} == {"CA004"}


def test_unknown_selector_is_a_usage_error() -> None:
    result = run("--select", "XX999", str(CLEAN))
    assert result.exit_code == 2
    assert "'XX999' matches no rule" in result.stderr
    assert "Traceback" not in result.output


def test_unknown_format_is_a_usage_error() -> None:
    result = run("--format", "yaml", str(CLEAN))
    assert result.exit_code == 2


def test_json_document_shape() -> None:
    result = run("--format", "json", str(BROKEN))
    document = json.loads(result.stdout)
    assert set(document) >= {"schema_version", "tool", "files", "summary"}
    assert document["schema_version"] == 1
    assert document["tool"]["name"] == "usdrender-lint"
    (file,) = document["files"]
    # config_file: added with a report that names each file's configuration.
    assert set(file) == {"file", "status", "error", "findings", "config_file"}
    assert file["status"] == "linted" and file["error"] is None
    keys = {"code", "name", "severity", "message", "path", "file", "layer", "line", "fix"}
    keys |= {"profile", "profile_reason"}  # added with renderer profiles (R2-5)
    keys |= {"column"}  # added with the text format's positions (issue 13)
    for finding in file["findings"]:
        assert set(finding) == keys
        assert finding["severity"] in ("error", "warning", "info")
        assert finding["fix"] is None or set(finding["fix"]) == {"description", "safe"}
    ca004 = next(f for f in file["findings"] if f["code"] == "CA004")
    assert ca004["path"] == "/Render/PrimarySettings.camera"
    assert ca004["layer"].endswith("broken_shot/shot.usda")
    assert isinstance(ca004["line"], int)
    assert ca004["fix"]["safe"] is True
    summary = document["summary"]
    assert summary["files"] == 1
    assert summary["findings"] == len(file["findings"])
    assert sum(summary["by_severity"].values()) == summary["findings"]


def test_info_hidden_in_text_unless_show_info(tmp_path: Path) -> None:
    layer = tmp_path / "info.usda"
    layer.write_text(
        '#usda 1.0\ndef Scope "Render"\n{\n    def RenderSettings "S"\n    {\n    }\n}\n'
    )
    as_json = findings_of(run("--format", "json", str(layer)).output)
    infos = [f for f in as_json if f["severity"] == "info"]
    assert infos  # ST003: no renderSettingsPrimPath, one RenderSettings
    hidden = run(str(layer)).output
    shown = run("--show-info", str(layer)).output
    assert infos[0]["code"] not in hidden.split("info hidden")[0]
    assert infos[0]["code"] in shown


def test_text_report_lines_start_with_the_layer_and_line() -> None:
    result = run("--select", ",".join(sorted(HEADLINE)), str(BROKEN), str(WIP))
    lines = result.output.splitlines()
    assert lines[0].startswith("examples/broken_shot/lighting_wip.usda:9:1: error ST001: ")
    assert any(line.startswith("examples/broken_shot/shot.usda:32: error CA004 ") for line in lines)
    assert "\x1b[" not in result.output  # not a terminal: no colour codes
    assert lines[-1] == (
        "6 findings in 2 files: 5 errors, 1 warning, 0 info; 2 fixable with --fix"
        " (1 more with --unsafe-fixes)."
    )


def test_rules_lists_every_rule_as_json() -> None:
    result = CliRunner().invoke(cli, ["rules", "--format", "json"])
    rows = json.loads(result.output)
    codes = [r["code"] for r in rows]
    assert set(codes) >= HEADLINE
    assert codes == sorted(codes)
    assert all(r["plugin"] == "builtin" for r in rows)


def test_rules_table() -> None:
    result = CliRunner().invoke(cli, ["rules"])
    assert result.exit_code == 0
    assert "camera-target-not-camera" in result.output


@pytest.mark.parametrize("key", ["CA004", "camera-target-not-camera", "ca004"])
def test_explain(key: str) -> None:
    result = CliRunner().invoke(cli, ["explain", key])
    assert result.exit_code == 0
    for section in (
        "## What it does",
        "## Why is this bad?",
        "## Example",
        "## Use instead",
        "## Fix safety",
    ):
        assert section in result.output


def test_explain_unknown_rule() -> None:
    result = CliRunner().invoke(cli, ["explain", "NOPE01"])
    assert result.exit_code == 2
    assert "no rule has the code or name" in result.stderr


def test_python_dash_m_entry_point() -> None:
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "usdrender_lint",
            "check",
            "--isolated",
            "--format",
            "json",
            str(BROKEN),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 1
    assert json.loads(proc.stdout)["summary"]["findings"] > 0
    assert proc.stderr == ""


def test_usd_warnings_never_reach_stderr(tmp_path: Path) -> None:
    layer = tmp_path / "dangling.usda"
    layer.write_text("#usda 1.0\n(\n    subLayers = [@./missing.usda@]\n)\n")
    proc = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--isolated", str(layer)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert "Warning" not in proc.stderr and "Traceback" not in proc.stderr


def test_a_bad_value_from_an_environment_variable_names_the_variable(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "a-file").write_text("")
    monkeypatch.setenv("USDRENDER_LINT_CACHE_DIR", str(tmp_path / "a-file"))
    result = CliRunner().invoke(cli, ["check", "--isolated", str(tmp_path)])
    assert result.exit_code == 2
    assert "(env var: 'USDRENDER_LINT_CACHE_DIR')" in result.stderr


@pytest.mark.parametrize("command", ["check", "merge", "spec"])
def test_help_of_each_reporting_command_gives_its_exit_codes(command: str) -> None:
    # check's exit codes are its contract with CI; merge's and spec's help give theirs.
    result = CliRunner().invoke(cli, [command, "--help"], terminal_width=100)
    text = " ".join(result.output.split())
    assert result.exit_code == 0
    assert "xit code" in text and " 2 " in text, text


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (["check", "--format", "x", "."], "Invalid value for '--format': 'x' is not one of"),
        (["check", "-j", "0", "."], "Invalid value for '--jobs' / '-j'"),
        (["spec"], "Missing argument 'PATHS...' (see 'usdrender-lint spec --help')"),
        (["chek", "."], "No such command 'chek'. Did you mean 'check'?"),
        (["--bogus"], "No such option '--bogus' (see 'usdrender-lint --help')"),
        (["rules", "--profile", "zz"], "(see 'usdrender-lint rules --help')"),
        # A ruff user's options are answered with ours.
        (["check", "--exit-zero", "."], "No such option '--exit-zero': use --fail-on never,"),
        (["check", "--output-format", "json", "."], "'--output-format': use --format,"),
        (["merge", "-o", "x.json", "r.json"], "No such option '-o': use --output,"),
        (["explain", "-o", "x", "SE003"], "No such option '-o' (see"),  # explain has no --output
        # click's parser gives these no context: the command's help all the same.
        (["check", "--fail-on"], "requires an argument (see 'usdrender-lint check --help')"),
        (["check", "--fix=yes", "."], "take a value (see 'usdrender-lint check --help')"),
        (["spec", "--format"], "requires an argument (see 'usdrender-lint spec --help')"),
    ],
)
def test_a_usage_error_is_one_line_as_every_other_error(args: list[str], said: str) -> None:
    """click's usage, hint and error over four lines read apart from the tool's
    other errors; one line names the command's help instead."""
    result = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", *args], capture_output=True, text=True
    )
    assert result.returncode == 2
    assert result.stderr.startswith("usdrender-lint: error: ") and said in result.stderr
    assert result.stderr.count("\n") == 1, result.stderr


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (["explain", "camera_unset"], "(did you mean 'camera-unset'? see 'usdrender-lint rules')"),
        (["explain", "CA0044"], "(did you mean 'CA004'?"),
        (["explain", "zzz"], "no rule has the code or name 'zzz' (see 'usdrender-lint rules')"),
        (
            ["check", "--select", "camera_unset", str(REPO / "examples")],
            "--select: 'camera_unset' matches no rule code, code prefix or rule name "
            "(did you mean 'camera-unset'?)",
        ),
    ],
)
def test_a_mistyped_rule_is_answered_with_the_nearest(args: list[str], said: str) -> None:
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 2
    assert said in result.stderr and result.stderr.count("\n") == 1
