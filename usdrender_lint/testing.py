"""Fixture harness for rule tests, shipped for plugin authors too.

A rule's fixture folder holds ``pass_*.usda`` files, which must give no finding
of the rule, and ``fail_*.usda`` files, which list the findings they expect on
comment lines (USD ignores them), usually right after the header::

    #usda 1.0
    # expect: SE003 </Render/Settings.dataWindowNDC>

Any other file in the folder is a supporting layer (a sublayer or a reference).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

from .api import Rule
from .engine import Linter
from .model import Finding
from .registry import build_registry

_EXPECT = re.compile(r"^#\s*expect:\s*([A-Z]+[0-9]+)\s+<([^>]*)>\s*$")


def expectations(path: str | Path) -> set[tuple[str, str]]:
    """The ``(code, path)`` pairs a fail fixture declares."""
    found = set()
    for line in Path(path).read_text(encoding="utf-8").splitlines()[1:]:
        match = _EXPECT.match(line.strip())
        if match:
            found.add((match.group(1), match.group(2)))
    return found


def all_rules() -> list[Rule]:
    return [rule() for rule in build_registry().rules]


def lint(path: str | Path, rules: Sequence[Rule] | None = None) -> list[Finding]:
    """Lint a file with every registered rule; a rule that raises fails the test."""
    linter = Linter(rules if rules is not None else all_rules(), raise_errors=True)
    result = linter.lint_path(str(path))
    assert result.status == "linted", result.error
    return list(result.findings)


def found_pairs(findings: Sequence[Finding], code: str) -> set[tuple[str, str]]:
    return {(f.code, f.location.path or "") for f in findings if f.code == code}


def fixture_files(folder: str | Path) -> list[Path]:
    folder = Path(folder)
    return sorted(
        p
        for p in folder.glob("*.usda")
        if p.name.startswith(("pass_", "fail_")) and not p.name.endswith(".fixed.usda")
    )


def check_fixture(path: str | Path, code: str, rules: Sequence[Rule] | None = None) -> None:
    """Assert a fixture behaves: pass files give no ``code`` finding, fail files
    give exactly the findings of ``code`` they declare."""
    path = Path(path)
    got = found_pairs(lint(path, rules), code)
    if path.name.startswith("pass_"):
        assert not got, f"{path.name}: expected no {code} finding, got {sorted(got)}"
        return
    expected = {pair for pair in expectations(path) if pair[0] == code}
    assert expected, f"{path.name}: a fail fixture must declare '# expect: {code} <path>'"
    assert got == expected, f"{path.name}: expected {sorted(expected)}, got {sorted(got)}"
