"""What a gate says: it shows what fails, it refuses what it cannot do, and
its messages carry no machine's absolute paths.

- ``--fail-on info`` shows the info findings it fails on, in text and in
  GitHub annotations (it failed with "0 findings (2 info hidden)").
- ``--ignore ST001`` is refused with a message (a file USD cannot open is
  never a silent pass); a wider selector (``ALL``, ``ST``) says so in a note.
- ST001's message does not repeat the file's absolute path: the location
  carries the file, line and column.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.formatters.github import escape_property

pytestmark = pytest.mark.heavy(seconds=12)

REPO = Path(__file__).resolve().parents[2]
INFO_ONLY = REPO / "tests" / "rules" / "ST003_render_settings_path_missing" / "fail_unset.usda"
WIP = REPO / "examples" / "broken_shot" / "lighting_wip.usda"


def check(*args: str):
    return CliRunner().invoke(cli, ["check", "--isolated", *args])


def test_fail_on_info_shows_the_info_findings_in_text() -> None:
    result = check("--select", "ST003", "--fail-on", "info", str(INFO_ONLY))
    assert result.exit_code == 1
    assert "info ST003" in result.stdout
    assert "hidden" not in result.stdout
    assert "1 finding in 1 file" in result.stdout


def test_fail_on_info_annotates_them_on_github() -> None:
    result = check("--select", "ST003", "--format", "github", "--fail-on", "info", str(INFO_ONLY))
    assert result.exit_code == 1
    assert result.stdout.startswith("::notice file=") and "title=ST003::" in result.stdout


def test_the_default_gate_still_hides_info() -> None:
    result = check("--select", "ST003", str(INFO_ONLY))
    assert result.exit_code == 0
    assert "1 info hidden" in result.stdout


@pytest.mark.parametrize("selector", ["ST001", "st001", "stage-open-failed"])
def test_ignoring_st001_itself_is_refused(selector: str) -> None:
    result = check("--ignore", selector, str(WIP))
    assert result.exit_code == 2
    assert result.stderr.count("\n") == 1
    assert f"--ignore: {selector!r} cannot be ignored: ST001 (stage-open-failed)" in result.stderr


def test_ignoring_st001_in_the_config_is_refused(tmp_path: Path) -> None:
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text('ignore = ["ST001"]\n')
    result = CliRunner().invoke(cli, ["check", "--config", str(config), str(WIP)])
    assert result.exit_code == 2
    assert "'ST001' cannot be ignored" in result.stderr


@pytest.mark.parametrize("selector", ["ALL", "ST"])
def test_a_wider_ignore_says_st001_stays(selector: str) -> None:
    result = check("--ignore", selector, "--format", "json", str(WIP))
    assert result.exit_code == 1
    codes = [f["code"] for f in json.loads(result.stdout)["files"][0]["findings"]]
    assert codes == ["ST001"]
    assert f"note: ignore {selector!r}: ST001 (stage-open-failed) is always reported" in (
        result.stderr
    )


@pytest.mark.parametrize("output_format", ["json", "sarif", "github", "text"])
def test_st001_does_not_repeat_the_absolute_path(output_format: str) -> None:
    result = check("--format", output_format, str(WIP))
    assert result.exit_code == 1
    message = "Expected } at '' in </Lights/key>"
    if output_format == "sarif":  # a brace is doubled in SARIF's text (SARIF 2.1.0 §3.11.5)
        message = message.replace("}", "}}")
    assert message in result.stdout
    # The file is named once per finding (where the format names it), not in the message.
    assert f"{WIP}:9:1: Expected" not in result.stdout
    if output_format == "json":
        (finding,) = json.loads(result.stdout)["files"][0]["findings"]
        assert finding["message"] == "Expected } at '' in </Lights/key>"
        assert (finding["line"], finding["column"]) == (9, 1)


# -- Git LFS pointers and absolute paths in messages ------------------------------------

LFS_POINTER = (
    "version https://git-lfs.github.com/spec/v1\n"
    "oid sha256:4d7a214614ab2935c943f9e0ff69d22eadbb8f32b1258daaa5e2ca24d17e2393\n"
    "size 12345\n"
)


@pytest.mark.parametrize("suffix", [".usd", ".usda", ".usdc"])
def test_a_git_lfs_pointer_is_named_as_such(tmp_path: Path, suffix: str) -> None:
    pointer = tmp_path / f"shot{suffix}"
    pointer.write_text(LFS_POINTER)
    result = check("--format", "json", str(pointer))
    assert result.exit_code == 1
    (finding,) = json.loads(result.stdout)["files"][0]["findings"]
    assert finding["code"] == "ST001"
    assert finding["message"].startswith("this is a Git LFS pointer, not the layer")
    assert "git lfs pull" in finding["message"]


def test_a_sublayer_that_is_a_git_lfs_pointer_is_named_and_paths_are_relative(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "lighting.usda").write_text(LFS_POINTER)
    (tmp_path / "shot.usda").write_text("#usda 1.0\n(\n    subLayers = [@./lighting.usda@]\n)\n")
    monkeypatch.chdir(tmp_path)
    for output_format in ("json", "github", "sarif", "text"):
        result = check("--format", output_format, "shot.usda")
        assert result.exit_code == 1
        assert "@lighting.usda@ is a Git LFS pointer, not the layer" in result.stdout
        # No absolute path leaks into a message (SARIF names the base folder its
        # URIs are relative to; an annotation's file is absolute for the runner,
        # which shows it relative to the repository).
        text = result.stdout.replace(f'"uri": "{tmp_path.as_uri()}/"', "")
        text = text.replace(f"::error file={escape_property(str(tmp_path))}/", "::error file=")
        assert str(tmp_path) not in text, output_format


def test_relative_in_rewrites_only_paths_below_the_directory() -> None:
    from usdrender_lint.paths import relative_in

    text = "@/ci/work/shot.usda@ and </ci/work/a.usda> but not /x/ci/work/b or /ci/workshop/c"
    assert relative_in(text, "/ci/work") == (
        "@shot.usda@ and <a.usda> but not /x/ci/work/b or /ci/workshop/c"
    )
    assert relative_in(text, "/") == text


@pytest.mark.parametrize(
    ("config", "refused"),
    [
        ('[per-path-ignores]\n"*_wip.usda" = ["ST001"]\n', "per-path-ignores.*_wip.usda: 'ST001'"),
        (
            '[per-path-ignores]\n"*_wip.usda" = ["stage-open-failed"]\n',
            "per-path-ignores.*_wip.usda: 'stage-open-failed'",
        ),
        ('[severity]\nST001 = "info"\n', "severity.ST001: ST001 is always an error"),
        ('[severity]\nstage-open-failed = "warning"\n', "severity.stage-open-failed: ST001"),
    ],
)
def test_silencing_st001_per_path_or_by_severity_is_refused(
    tmp_path: Path, config: str, refused: str
) -> None:
    """As ``--ignore ST001``: a file that fails to open passed the gate with exit 0."""
    (tmp_path / ".usdrender-lint.toml").write_text(config)
    result = CliRunner().invoke(
        cli, ["check", "--config", str(tmp_path / ".usdrender-lint.toml"), str(WIP)]
    )
    assert result.exit_code == 2
    assert refused in result.stderr and result.stderr.count("\n") == 1


def test_a_wider_per_path_ignore_keeps_st001(tmp_path: Path) -> None:
    (tmp_path / ".usdrender-lint.toml").write_text('[per-path-ignores]\n"*.usda" = ["ALL"]\n')
    result = CliRunner().invoke(
        cli,
        ["check", "--config", str(tmp_path / ".usdrender-lint.toml"), "--format", "json", str(WIP)],
    )
    assert result.exit_code == 1
    codes = {f["code"] for file in json.loads(result.stdout)["files"] for f in file["findings"]}
    assert codes == {"ST001"}


def test_diff_and_write_baseline_together_are_refused_before_anything_is_written(
    tmp_path: Path,
) -> None:
    """--diff's exit code says whether a fix is pending (1), --write-baseline's
    that the baseline was written (0): one run cannot say both, so it is a
    usage error, as --baseline with --write-baseline is."""
    baseline = tmp_path / "baseline.json"
    result = check("--diff", "--write-baseline", str(baseline), str(INFO_ONLY))
    assert result.exit_code == 2 and not baseline.exists()
    assert (result.stdout, result.stderr) == (
        "",
        "usdrender-lint: error: use either --diff or --write-baseline, not both: --diff exits "
        "1 when a fix is pending, --write-baseline exits 0 once written\n",
    )
    # Apart, each does its job.
    assert check("--diff", str(INFO_ONLY)).exit_code == 1
    assert check("--write-baseline", str(baseline), str(INFO_ONLY)).exit_code == 0
