"""The exit codes the reference page gives for the commands other than check."""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner

from usdrender_lint.cli import cli

REPO = Path(__file__).resolve().parents[2]
PAGE = (REPO / "docs" / "reference" / "exit-codes.md").read_text(encoding="utf-8")


def test_explain_rules_and_spec_exit_as_documented(tmp_path: Path) -> None:
    assert "| `explain` | 0, or 2 when no rule has that code or name |" in PAGE
    assert CliRunner().invoke(cli, ["explain", "CA004"]).exit_code == 0
    assert CliRunner().invoke(cli, ["explain", "NOPE999"]).exit_code == 2
    assert "| `rules` | 0 |" in PAGE
    assert CliRunner().invoke(cli, ["rules"]).exit_code == 0
    assert "| `spec` | 0 when every file's specification was computed, 2 when" in PAGE
    missing = CliRunner().invoke(cli, ["spec", "--jobs", "1", str(tmp_path / "missing.usda")])
    assert missing.exit_code == 2
