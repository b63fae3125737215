"""The example plugin, installed beside usdrender-lint: its rules register
through the entry point group, run from the command line and pass their
fixtures with the shipped harness."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from acme_render_rules import RULES, AcmeProductRule, ProductNameFrameToken

from usdrender_lint.registry import build_registry
from usdrender_lint.testing import check_fixture, lint_text

# Kept here rather than as .usda files: `usdrender-lint check examples/` lints
# every layer under examples/, and these are meant to fail.
PRODUCT = """#usda 1.0
{expect}
def Scope "Render"
{{
    def RenderProduct "beauty"
    {{
        token productName = "{name}"
    }}
}}
"""
FIXTURES = {
    "fail_no_token.usda": PRODUCT.format(
        expect='# expect: ACME001 </Render/beauty.productName> x1 fix "has no frame token"',
        name="beauty.exr",
    ),
    "fail_absolute.usda": PRODUCT.format(
        expect='# expect: ACME002 </Render/beauty.productName> x1 nofix "is absolute"',
        name="/mnt/r/beauty.####.exr",
    ),
    "pass_conventions.usda": PRODUCT.format(expect="", name="beauty.####.exr"),
}


def test_the_rules_register_through_the_entry_point() -> None:
    registry = build_registry()
    assert {"ACME001", "ACME002"} <= {rule.code for rule in registry.rules}
    assert registry.origins["ACME001"] == "acme"
    assert AcmeProductRule not in registry.rules  # abstract: not a rule


CASES = [
    ("fail_no_token.usda", "ACME001"),
    ("fail_absolute.usda", "ACME002"),
    *(("pass_conventions.usda", rule.code) for rule in RULES),
]


@pytest.mark.parametrize(("name", "code"), CASES)
def test_fixtures(tmp_path: Path, name: str, code: str) -> None:
    path = tmp_path / name
    path.write_text(FIXTURES[name])
    check_fixture(path, code)


def test_the_command_runs_and_fixes_them(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(PRODUCT.format(expect="", name="beauty.exr"))
    command = [sys.executable, "-m", "usdrender_lint", "check", "--isolated"]
    listed = subprocess.run(
        [*command, "--format", "json", "--select", "ACME", str(shot)],
        capture_output=True, text=True,
    )  # fmt: skip
    assert listed.returncode == 0  # a warning does not fail by default
    codes = [f["code"] for f in json.loads(listed.stdout)["files"][0]["findings"]]
    assert codes == ["ACME001"]
    fixed = subprocess.run(
        [*command, "--fix", "--select", "ACME", str(shot)], capture_output=True, text=True
    )
    assert fixed.returncode == 0, fixed.stderr
    assert 'productName = "beauty.####.exr"' in shot.read_text()


def test_the_token_option(tmp_path: Path) -> None:
    """A rule with options is tested with an instance made with them; the
    command reads them from [tool.usdrender-lint.rules.<name>]."""
    houdini = ProductNameFrameToken(ProductNameFrameToken.Options(token="$F4"))
    path = tmp_path / "fail_houdini_token.usda"
    path.write_text(
        PRODUCT.format(
            expect='# expect: ACME001 </Render/beauty.productName> x1 fix "no frame token $F4"',
            name="beauty.####.exr",
        )
    )
    check_fixture(path, "ACME001", rules=[houdini])
    text = PRODUCT.format(expect="", name="beauty.$F4.exr")
    assert lint_text(text, rules=[houdini]) == []
    assert [f.code for f in lint_text(text, select=["ACME001"])] == ["ACME001"]  # the default
    (tmp_path / "pyproject.toml").write_text(
        '[tool.usdrender-lint.rules.product-name-frame-token]\ntoken = "$F4"\n'
    )
    (tmp_path / "shot.usda").write_text(text)
    listed = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--select", "ACME", "shot.usda"],
        capture_output=True, text=True, cwd=tmp_path,
    )  # fmt: skip
    assert (listed.returncode, listed.stderr) == (0, ""), listed.stderr
    assert "ACME001" not in listed.stdout
