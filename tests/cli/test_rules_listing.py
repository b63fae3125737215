"""``rules`` prints every rule in full whatever the width, and ``explain``
knows every code the README and the hand-written documentation name."""

from __future__ import annotations

import fcntl
import os
import pty
import re
import struct
import subprocess
import sys
import termios
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli, rules_text
from usdrender_lint.registry import build_registry

REPO = Path(__file__).resolve().parents[2]
RULES = build_registry().rules


def rows() -> list[tuple[str, str, str, str, str]]:
    return [(r.code, r.name, r.severity.value, r.fix_safety, r.summary()) for r in RULES]


def test_piped_every_rule_is_one_line_with_everything_in_full() -> None:
    result = CliRunner().invoke(cli, ["rules"])
    assert result.exit_code == 0
    lines = result.stdout.splitlines()
    assert lines[0] == f"{len(RULES)} rules"
    assert len(lines) == len(RULES) + 1
    for line, (code, name, severity, fix, summary) in zip(lines[1:], rows(), strict=True):
        assert line.split()[:4] == [code, name, severity, fix]
        assert line.endswith("  " + summary)
        assert "…" not in line


def in_a_terminal(columns: int, *args: str) -> str:
    """Run the command with its stdout on a pseudo-terminal ``columns`` wide."""
    leader, follower = pty.openpty()
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, columns, 0, 0))
    env = {k: v for k, v in os.environ.items() if k not in ("COLUMNS", "LINES")}
    process = subprocess.Popen(
        [sys.executable, "-m", "usdrender_lint", *args],
        stdout=follower,
        stderr=subprocess.PIPE,
        env=env,
    )
    os.close(follower)
    chunks = []
    while True:
        try:
            chunk = os.read(leader, 65536)
        except OSError:  # EIO: the terminal's other end is closed
            break
        if not chunk:
            break
        chunks.append(chunk)
    os.close(leader)
    assert process.wait(timeout=120) == 0
    return b"".join(chunks).decode().replace("\r\n", "\n")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="pseudo-terminals")
def test_at_60_columns_nothing_is_cut() -> None:
    text = in_a_terminal(60, "rules")
    assert max(len(line) for line in text.splitlines()) <= 60
    words = text.split()
    for code, name, severity, fix, summary in rows():
        at = words.index(code)
        assert words[at : at + 4] == [code, name, f"({severity},", "fix:"]
        assert words[at + 4] == f"{fix})"
        assert " ".join(summary.split()) in " ".join(words)
    assert "…" not in text


def test_rules_text_wraps_only_what_does_not_fit() -> None:
    wide = rules_text(rows(), 1000, "title").splitlines()
    assert wide == rules_text(rows(), None, "title").splitlines()
    narrow = rules_text(rows(), 60, "title").splitlines()
    assert len(narrow) > len(wide)
    assert all(
        line.startswith("    ") or line.split()[0] in {r.code for r in RULES} for line in narrow[1:]
    )


def documented_codes() -> set[str]:
    pages = [REPO / "README.md", *sorted((REPO / "docs").rglob("*.md"))]
    text = "\n".join(page.read_text(encoding="utf-8") for page in pages)
    # The built-in families; ACME001 is the third-party example of the plugin guide.
    return set(re.findall(r"\b(?:ST|SE|CA|PR|VA|PA|UL|KA|RM|AR|OV)\d{3}\b", text))


@pytest.mark.parametrize("code", sorted(documented_codes()))
def test_explain_knows_every_code_the_docs_name(code: str) -> None:
    result = CliRunner().invoke(cli, ["explain", code])
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith(f"{code} ")
    assert "## What it does" in result.stdout


def test_the_docs_name_the_internal_error_code() -> None:
    assert "UL000" in documented_codes()


@pytest.mark.parametrize("key", ["UL000", "ul000", "internal-error", " UL000 ", "internal-error "])
def test_explain_the_internal_error(key: str) -> None:
    result = CliRunner().invoke(cli, ["explain", key])
    assert result.exit_code == 0
    assert result.stdout.splitlines()[0] == "UL000 internal-error (error, fix: none)"
    assert "ST001" in result.stdout  # corrupt values are the file's problem


@pytest.mark.parametrize("typo", ["UL0000", "internal-eror"])
def test_a_mistyped_internal_error_is_offered_it(typo: str) -> None:
    """Before, no code or name of it was ever offered."""
    result = CliRunner().invoke(cli, ["explain", typo])
    assert result.exit_code == 2
    near = "UL000" if typo.startswith("UL") else "internal-error"
    assert f"did you mean {near!r}?" in result.stderr


# -- the rules check runs here: the configuration's selection, severities and profile --

PROJECT = """select = ["SE", "CA001"]
ignore = ["SE002"]
[severity]
SE001 = "info"
"""


def listed(folder: Path, monkeypatch: pytest.MonkeyPatch, *args: str) -> dict[str, dict]:
    """``rules --format json`` run in ``folder``: each rule's entry by code."""
    import json

    monkeypatch.chdir(folder)
    result = CliRunner().invoke(cli, ["rules", "--format", "json", *args])
    assert result.exit_code == 0, result.output
    return {item["code"]: item for item in json.loads(result.stdout)}


def enabled(items: dict[str, dict]) -> set[str]:
    return {code for code, item in items.items() if item["enabled"]}


SE = {r.code for r in RULES if r.code.startswith("SE")}


@pytest.mark.parametrize("profile", [(), ("--profile", "karma")])
def test_rules_in_a_project_are_those_check_runs_there(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, profile: tuple[str, ...]
) -> None:
    """Before, --profile listed every rule the profile keeps, whatever the
    configuration selected, ignored or made info; without it no rule said
    whether it runs."""
    (tmp_path / ".usdrender-lint.toml").write_text(PROJECT, encoding="utf-8")
    items = listed(tmp_path, monkeypatch, *profile)
    assert enabled(items) == (SE - {"SE002"}) | {"CA001"}
    assert items["SE001"]["effective_severity"] == "info"
    assert "severity.SE001" in items["SE001"]["why"]
    assert items["SE002"]["why"].endswith(".usdrender-lint.toml: ignore")
    assert items["CA002"]["why"].endswith(".usdrender-lint.toml: select")


def test_rules_take_the_configured_profile_and_the_flags(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / ".usdrender-lint.toml").write_text('profile = "arnold"\n', encoding="utf-8")
    items = listed(tmp_path, monkeypatch)
    assert {item["profile"] for item in items.values()} == {"arnold"}
    assert "AR001" in enabled(items) and "KA001" not in enabled(items)
    # --profile wins over the file's, as check's does; the selection flags over its keys.
    items = listed(tmp_path, monkeypatch, "--profile", "karma", "--select", "KA,AR")
    assert enabled(items) == {r.code for r in RULES if r.code.startswith("KA")}
    # --isolated: every rule at its default severity, as without a configuration.
    items = listed(tmp_path, monkeypatch, "--isolated")
    assert [item["code"] for item in items.values()] == [r.code for r in RULES]
    assert "profile" not in items["AR001"] and "enabled" not in items["AR001"]


def test_rules_stop_on_a_bad_configuration_as_check_does(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / ".usdrender-lint.toml"
    path.write_text('fail-on = "error"\nselect = ["NOPE"]\n', encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(cli, ["rules", "--profile", "karma"])
    assert result.exit_code == 2
    assert result.stderr.strip() == (
        f"usdrender-lint: error: {path}:2: select: 'NOPE' matches no rule code, code prefix "
        "or rule name"
    )


def test_rules_in_a_working_directory_that_is_gone_is_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """It looks for the configuration from there, as check does (it was an internal error)."""
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    result = CliRunner().invoke(cli, ["rules"])
    assert result.exit_code == 2
    assert result.stderr.startswith("usdrender-lint: error: the working directory cannot be read")
    assert CliRunner().invoke(cli, ["rules", "--isolated"]).exit_code == 0
