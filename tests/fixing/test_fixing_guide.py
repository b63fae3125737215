"""The fixing guide (docs/guides/fixing.md) stays true: its table lists each
rule with a fix and its fix class, and its --fix-to example is what --fix-to
writes."""

from __future__ import annotations

import re
from pathlib import Path

from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.registry import build_registry

GUIDE = Path(__file__).parents[2] / "docs" / "guides" / "fixing.md"
CLASSES = {"safe": "safe", "safe, conditional": "safe-conditional", "unsafe": "unsafe"}


def fixing_section() -> str:
    return GUIDE.read_text(encoding="utf-8")


def test_the_table_shows_each_fix_class() -> None:
    rows = re.findall(r"^\| `(\w+)` ([\w-]+) \| ([\w, ]+) \| ", fixing_section(), re.MULTILINE)
    listed = {code: (name, CLASSES[fix_class]) for code, name, fix_class in rows}
    expected = {
        rule.code: (rule.name, rule.fix_safety)
        for rule in build_registry().rules
        if rule.fix_safety != "none" and rule.__module__.startswith("usdrender_lint.rules")
    }
    assert listed == expected


def test_the_fix_to_example_is_what_fix_to_writes(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(
        '#usda 1.0\n\ndef Scope "Render"\n{\n    def RenderSettings "Settings"\n    {\n'
        '        uniform token aspectRatioConformPolicy = "cropaperture"\n    }\n}\n',
        encoding="utf-8",
    )
    fixed = tmp_path / "fixed.usda"
    args = ["check", "--isolated", "-j", "1", "--select", "SE006,ST003", "--fix-to", str(fixed)]
    result = CliRunner().invoke(cli, [*args, str(shot)])
    assert result.exit_code == 0, result.output
    pattern = r"instead of the original root:\n\n```usda\n(.*?)```"
    example = re.search(pattern, fixing_section(), re.DOTALL)
    assert example is not None
    assert fixed.read_text(encoding="utf-8") == example.group(1) + "\n"
