"""The README's examples stay true."""

from __future__ import annotations

import re
from pathlib import Path

from usdrender_lint.api.docs import code_blocks, sections
from usdrender_lint.engine import Linter

README = Path(__file__).parents[2] / "README.md"


def test_third_party_rule_example_works(tmp_path: Path) -> None:
    text = README.read_text(encoding="utf-8")
    source = re.search(r"```python\n(# acme_rules\.py\n.*?)\n```\n", text, re.DOTALL).group(1)
    namespace: dict = {}
    exec(compile(source, "acme_rules.py", "exec"), namespace)  # noqa: S102 - our own README
    (rule_class,) = namespace["RULES"]
    doc = sections(rule_class)
    for section, fires in (("Example", True), ("Use instead", False)):
        layer = tmp_path / f"{fires}.usda"
        layer.write_text(code_blocks(doc[section])[0])
        result = Linter([rule_class()], raise_errors=True).lint_path(str(layer))
        assert any(f.code == "ACME001" for f in result.findings) is fires


def test_ci_runs_the_readme_test_command_exactly() -> None:
    text = README.read_text(encoding="utf-8")
    command = re.search(r"```sh\n(python3 -m venv .* -m pytest[^\n]*)\n```", text).group(1)
    ci = (README.parent / ".ci" / "run").read_text(encoding="utf-8")
    assert command in ci.splitlines()
