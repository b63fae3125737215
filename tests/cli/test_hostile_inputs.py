"""Inputs a gate must never skip or choke on: configuration files that are not
TOML, files and folders it may not read, file names that are not UTF-8, and
folders with nothing to lint."""

from __future__ import annotations

import ctypes
import json
import os
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.paths import escape

pytestmark = pytest.mark.heavy(seconds=15)

REPO = Path(__file__).resolve().parents[2]
CLEAN = (REPO / "examples" / "clean_shot" / "shot.usda").read_text()
INVERTED = """#usda 1.0
(
    subLayers = [@./sub.usda@]
)
def Scope "Render"
{
    def RenderSettings "S"
    {
        uniform float4 dataWindowNDC = (1, 1, 0, 0)
    }
}
"""


def check(*args: str, cwd: Path | None = None):
    return CliRunner().invoke(cli, ["check", "--jobs", "1", *args])


# -- configuration files that are not TOML ------------------------------------------


@pytest.mark.parametrize(
    ("name", "text", "position", "reason"),
    [
        ("pyproject.toml", '[project]\nname = "x"\nversion = \n', "3:11", "Invalid value"),
        ("pyproject.toml", "[tool.usdrender-lint\n", "1:21", "Expected ']'"),
        (".usdrender-lint.toml", 'select = ["SE"\nignore = []\n', "2:1", "Unclosed array"),
        (
            ".usdrender-lint.toml",
            "fail-on = 'error'\nfail-on = 'warning'\n",
            "2:20",
            "Cannot overwrite",
        ),
        (".usdrender-lint.toml", "select = [", "1:11", "Invalid value"),
    ],
)
def test_a_config_file_that_is_not_toml_stops_the_run_with_its_position(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    name: str,
    text: str,
    position: str,
    reason: str,
) -> None:
    """Today's bug: a broken pyproject.toml was skipped, and the run used the defaults."""
    (tmp_path / name).write_text(text)
    (tmp_path / "shot.usda").write_text(CLEAN)
    monkeypatch.chdir(tmp_path)
    result = check("shot.usda")
    assert result.exit_code == 2
    [line] = result.stderr.splitlines()
    assert line.startswith(f"usdrender-lint: error: {tmp_path / name}:{position}: invalid TOML: ")
    assert reason in line
    assert result.stdout == ""


def test_a_config_file_that_is_not_utf8_names_the_byte(tmp_path: Path) -> None:
    config = tmp_path / ".usdrender-lint.toml"
    config.write_bytes(b'select = ["SE"]\nignore = ["\xff"]\n')
    result = check("--config", str(config), str(tmp_path))
    assert result.exit_code == 2
    assert result.stderr == (
        f"usdrender-lint: error: {config}:2:12: invalid TOML: not UTF-8 (byte 0xff)\n"
    )


# -- files and folders that may not be read -----------------------------------------


def _without_permission_bypass() -> None:
    """In the child, before it runs the command: drop the capabilities that let
    root ignore permissions (CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH) from the
    bounding set, so the command runs under the permission bits like any user."""
    libc = ctypes.CDLL(None, use_errno=True)
    for capability in (1, 2):
        if libc.prctl(24, capability, 0, 0, 0) != 0:  # 24: PR_CAPBSET_DROP
            os._exit(97)


def run_unprivileged(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    """The command as permissions apply to it. As root (who reads anything) the
    child gives up the capabilities that bypass them: the checks are real, not
    emulated. A system that refuses that skips the test."""
    root = os.geteuid() == 0
    if root and not sys.platform.startswith("linux"):
        pytest.skip("running as root, and only Linux lets a child give up reading anything")
    result = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        preexec_fn=_without_permission_bypass if root else None,  # noqa: PLW1509
        timeout=300,
    )
    if result.returncode == 97:
        pytest.skip("running as root, and this system does not let a child drop its capabilities")
    return result


@pytest.fixture
def locked_tree(tmp_path: Path) -> Iterator[Path]:
    tree = tmp_path / "tree"
    for folder in ("locked", "noexec", "ok"):
        (tree / folder).mkdir(parents=True)
        (tree / folder / "shot.usda").write_text(CLEAN)
    (tree / "ok" / "secret.usda").write_text(CLEAN)
    (tree / "ok" / "secret.usda").chmod(0)
    (tree / "locked").chmod(0)  # cannot be listed
    (tree / "noexec").chmod(0o644)  # listed, but nothing in it can be opened
    yield tree
    for folder in ("locked", "noexec"):
        (tree / folder).chmod(0o755)  # so that pytest can remove it


def test_unreadable_files_and_folders_are_reported_never_skipped(
    tmp_path: Path, locked_tree: Path
) -> None:
    result = run_unprivileged("check", "--isolated", "tree", cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        "usdrender-lint: error: tree/locked: permission denied",
        "usdrender-lint: error: tree/noexec/shot.usda: permission denied",
        "usdrender-lint: error: tree/ok/secret.usda: permission denied",
    ]
    # The readable file is linted all the same (this replaces an emulation of
    # os.access: the permission checks here are the kernel's).
    assert "4 files" in result.stdout.splitlines()[-1]


def test_a_file_in_a_folder_without_search_permission_is_not_missing(
    tmp_path: Path, locked_tree: Path
) -> None:
    result = run_unprivileged(
        "check", "--isolated", "--format", "json", "tree/noexec/shot.usda", cwd=tmp_path
    )
    assert result.returncode == 2
    [entry] = json.loads(result.stdout)["files"]
    assert entry["error"] == "tree/noexec/shot.usda: permission denied"


def test_an_unreadable_pyproject_stops_the_run(tmp_path: Path) -> None:
    (tmp_path / "pyproject.toml").write_text("[tool.usdrender-lint]\n")
    (tmp_path / "pyproject.toml").chmod(0)
    (tmp_path / "shot.usda").write_text(CLEAN)
    result = run_unprivileged("check", "shot.usda", cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr == (
        f"usdrender-lint: error: {tmp_path / 'pyproject.toml'}: cannot read config file: "
        "Permission denied\n"
    )


# -- file names that are not UTF-8 ----------------------------------------------------


@pytest.fixture
def undecodable(tmp_path: Path) -> Path:
    """``caf\\xe9 x.usda`` (Latin-1) sublayering ``sub.usda``."""
    try:
        name = os.fsdecode(b"caf\xe9 x.usda")
        (tmp_path / name).write_text(INVERTED)
    except (OSError, UnicodeError):
        pytest.skip("the file system takes only UTF-8 names")
    (tmp_path / "sub.usda").write_text("#usda 1.0\n")
    return tmp_path / name


def unescape(text: str) -> bytes:
    """The inverse of usdrender_lint.paths.escape."""
    return re.sub(
        rb"\\\\|\\x([0-9a-f]{2})",
        lambda m: bytes([int(m.group(1), 16)]) if m.group(1) else b"\\",
        text.encode("utf-8"),
    )


@pytest.mark.parametrize("raw", [b"caf\xe9.usda", b"a\\xe9 \xe9\\.usda", "渲染 é.usda".encode()])
def test_the_escaped_form_is_lossless(raw: bytes) -> None:
    name = os.fsdecode(raw)
    shown = escape(name)
    shown.encode("utf-8")  # any UTF-8 output carries it
    assert unescape(shown) == raw if shown != name else name == raw.decode()


def test_a_name_that_is_not_utf8_is_linted_and_named_losslessly(undecodable: Path) -> None:
    shown = escape(str(undecodable))
    assert shown.endswith("caf\\xe9 x.usda")
    assert unescape(shown) == os.fsencode(undecodable)
    text = check("--isolated", str(undecodable))
    assert text.exit_code == 1
    assert f"{shown}:9: error SE003 " in text.stdout  # linted, its sublayer found
    assert "ST002" not in text.stdout and "ST001" not in text.stdout


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_json_and_sarif_stay_valid_documents(undecodable: Path, jobs: str) -> None:
    shown = escape(str(undecodable))
    as_json = check("--isolated", "--jobs", jobs, "--format", "json", str(undecodable))
    document = json.loads(as_json.stdout)
    assert [f["file"] for f in document["files"]] == [shown]
    assert {f["code"] for f in document["files"][0]["findings"]} >= {"SE003"}
    as_sarif = check("--isolated", "--jobs", jobs, "--format", "sarif", str(undecodable))
    sarif = json.loads(as_sarif.stdout)
    uris = {
        location["physicalLocation"]["artifactLocation"]["uri"]
        for result in sarif["runs"][0]["results"]
        for location in result["locations"]
    }
    assert any(uri.endswith("caf%E9%20x.usda") for uri in uris), uris


def test_output_and_github_take_such_a_name(undecodable: Path, tmp_path: Path) -> None:
    report = tmp_path / "report.sarif"
    result = check("--isolated", "--format", "sarif", "--output", str(report), str(undecodable))
    assert result.exit_code == 1, result.output
    json.loads(report.read_text(encoding="utf-8"))
    github = check("--isolated", "--format", "github", str(undecodable))
    assert "caf\\xe9" in github.stdout


def test_a_composition_error_naming_such_a_file_is_st002(undecodable: Path) -> None:
    (undecodable.parent / "sub.usda").unlink()
    result = check("--isolated", "--format", "json", str(undecodable))
    [entry] = json.loads(result.stdout)["files"]
    st002 = [f["message"] for f in entry["findings"] if f["code"] == "ST002"]
    assert st002 and escape(str(undecodable)) in st002[0]
    assert "not valid UTF-8" not in result.stdout


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_a_parse_error_of_such_a_name_is_told_once_at_its_line(tmp_path: Path, jobs: str) -> None:
    # USD's message quotes the name, which Python cannot decode: the text is
    # parsed again under no name for USD's words.
    try:
        path = tmp_path / os.fsdecode(b"caf\xe9.usda")
        path.write_text('#usda 1.0\ndef Scope "S" { rel camera = </Nope> }\n')
    except (OSError, UnicodeError):
        pytest.skip("the file system takes only UTF-8 names")
    result = CliRunner().invoke(
        cli, ["check", "--isolated", "--no-cache", "--jobs", jobs, "--format", "json", str(path)]
    )
    [entry] = json.loads(result.stdout)["files"]
    [finding] = entry["findings"]
    assert (finding["code"], finding["line"], finding["column"]) == ("ST001", 2, 17)
    assert finding["message"] == "Expected } at 'rel camera = </Nope> }' in </S>"


def test_an_error_about_such_a_name_is_escaped_on_stderr(tmp_path: Path) -> None:
    missing = os.fsdecode(b"gon\xe9.usda")
    result = check("--isolated", str(tmp_path / missing))
    assert result.exit_code == 2
    assert (
        result.stderr == f"usdrender-lint: error: {escape(str(tmp_path / missing))}: no such file\n"
    )


@pytest.mark.parametrize("name", ["a\nb.usda", "a\rb.usda", "a\u2028b.usda"])
def test_a_line_break_in_a_file_name_ends_no_line_of_usds_error(
    name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # USD names the file in its error: one parse error is one finding, at its line.
    (tmp_path / name).write_text('#usda 1.0\ndef Scope "S"\n{\n', encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    for path in (name, str(tmp_path / name)):
        result = check("--isolated", "--no-cache", "--format", "json", path)
        [entry] = json.loads(result.stdout)["files"]
        [finding] = entry["findings"]
        assert (finding["code"], finding["line"]) == ("ST001", 4), finding
        assert finding["layer"] == name


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_a_utf8_name_under_a_posix_locale_without_utf8_mode(tmp_path: Path, jobs: str) -> None:
    # Python's file system encoding is then ASCII: "é" is two surrogate escapes, while
    # USD's bindings hand the layer's path back decoded as UTF-8, which os.stat refused
    # (the file was an internal error: UnicodeEncodeError).
    inverted = INVERTED.replace("(\n    subLayers = [@./sub.usda@]\n)\n", "")
    (tmp_path / "sub-\u00e9.usda").write_text(inverted, encoding="utf-8")
    (tmp_path / "shot-\u00fc.usda").write_text(
        "#usda 1.0\n(\n    subLayers = [@./sub-\u00e9.usda@]\n)\n", encoding="utf-8"
    )
    env = {**os.environ, "LANG": "C", "LC_ALL": "C", "PYTHONUTF8": "0"}
    command = [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "--jobs", jobs]
    result = subprocess.run(
        [*command, "--format", "json", "shot-\u00fc.usda".encode(), "sub-\u00e9.usda".encode()],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        check=False,
    )
    assert result.returncode == 1, result.stderr
    assert not result.stderr
    files = json.loads(result.stdout)["files"]
    assert [(f["file"], f["status"]) for f in files] == [
        ("shot-\u00fc.usda", "linted"),
        ("sub-\u00e9.usda", "linted"),
    ]
    for entry in files:  # the sublayer's finding, named as the file is
        assert ("SE003", "sub-\u00e9.usda") in {(f["code"], f["layer"]) for f in entry["findings"]}


# -- folders with nothing to lint ---------------------------------------------------


def test_an_existing_folder_with_no_usd_files_is_a_warning_and_exit_0(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("no layers here")
    result = check("--isolated", str(tmp_path))
    assert result.exit_code == 0
    assert result.stderr == (
        f"usdrender-lint: warning: {tmp_path}: no USD files (.usd, .usda, .usdc, .usdz) in it\n"
    )


def test_the_warning_does_not_hide_the_other_paths(tmp_path: Path) -> None:
    (tmp_path / "empty").mkdir()
    (tmp_path / "shot.usda").write_text(INVERTED.replace("@./sub.usda@", "@./shot.usda@"))
    result = check(
        "--isolated", "--select", "SE003", str(tmp_path / "empty"), str(tmp_path / "shot.usda")
    )
    assert result.exit_code == 1
    assert "no USD files" in result.stderr and "SE003" in result.stdout


# -- a working directory USD cannot open files under --------------------------------


def _run_in(folder: Path, *args: str) -> subprocess.CompletedProcess:
    """The command started in ``folder`` (entered step by step: its path may be
    longer than any path the system takes in one call)."""
    code = (
        "import os, sys\n"
        "for part in sys.argv[1].split('/'):\n"
        "    os.chdir(part or '/')\n"
        "from usdrender_lint.cli import main\n"
        "sys.argv = ['usdrender-lint', *sys.argv[2:]]\n"
        "main()\n"
    )
    return subprocess.run(
        [sys.executable, "-c", code, str(folder), *args],
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.fixture
def too_deep(tmp_path: Path) -> Path:
    """A folder whose path is longer than PATH_MAX, holding a shot."""
    folder = tmp_path
    here = os.getcwd()
    os.chdir(tmp_path)
    try:
        while len(os.fsencode(str(folder))) <= 4200:
            os.mkdir("d" * 200)
            os.chdir("d" * 200)
            folder = folder / ("d" * 200)
        with open("shot.usda", "w") as handle:
            handle.write(INVERTED.replace("@./sub.usda@", "@./shot.usda@"))
    finally:
        os.chdir(here)
    return folder


def test_a_working_directory_longer_than_path_max_is_one_line(too_deep: Path) -> None:
    result = _run_in(too_deep, "check", "shot.usda")
    assert result.returncode == 2
    [line] = result.stderr.splitlines()
    assert re.fullmatch(
        r"usdrender-lint: error: the working directory's path is [\d,]+ bytes long, more than "
        r"PATH_MAX \([\d,]+\): USD cannot open files below it; change to a folder with a "
        r"shorter path",
        line,
    )
    assert result.stdout == ""


def test_absolute_paths_still_work_from_there(too_deep: Path) -> None:
    clean = str(REPO / "examples" / "clean_shot" / "shot.usda")
    result = _run_in(too_deep, "check", clean)
    assert (result.returncode, result.stderr) == (0, "")


def test_a_working_directory_that_is_gone_is_one_line(tmp_path: Path) -> None:
    gone = tmp_path / "gone"
    gone.mkdir()
    code = (
        "import os, sys\n"
        "os.chdir(sys.argv[1]); os.rmdir(sys.argv[1])\n"
        "from usdrender_lint.cli import main\n"
        "sys.argv = ['usdrender-lint', 'check', 'shot.usda']\n"
        "main()\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", code, str(gone)], capture_output=True, text=True, timeout=300
    )
    assert result.returncode == 2
    assert result.stderr == (
        "usdrender-lint: error: the working directory cannot be read (No such file or "
        "directory); change to another folder or give absolute paths\n"
    )
