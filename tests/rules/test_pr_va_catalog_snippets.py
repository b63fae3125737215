"""The catalog's failing snippets (../shared/spec/snippets), for the PR and VA
families: each fires its own rule, and the PR/VA rules that fire are exactly
the ones the catalog lists ("Other rules that also fire on the failing
snippet")."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from usdrender_lint.rules import products, vars
from usdrender_lint.testing import lint

FAMILY_RULES = [rule() for rule in (*products.RULES, *vars.RULES)]
FAMILY_CODES = {rule.code for rule in FAMILY_RULES}
_SECTION = re.compile(
    r"^### ([A-Z]{2}\d{3}) .*?\*Verified \(usd-core 26\.11\): OK\.\*"
    r"(?: Other rules that also fire on the failing snippet: ([^\n]*))?",
    re.MULTILINE | re.DOTALL,
)


def _catalog_expectations(shared_dir: Path) -> dict[str, set[str]]:
    catalog = (shared_dir / "spec" / "rule-catalog.md").read_text(encoding="utf-8")
    found = {}
    for match in _SECTION.finditer(catalog):
        others = {c.strip(" .") for c in (match.group(2) or "").split(",")}
        found[match.group(1)] = {match.group(1), *others} & FAMILY_CODES
    return found


def test_snippets_fire_what_the_catalog_says(shared_dir: Path) -> None:
    expected = _catalog_expectations(shared_dir)
    snippets = sorted((shared_dir / "spec" / "snippets").glob("*.usda"))
    checked = 0
    for snippet in snippets:
        code = snippet.name[:5]
        if code not in expected or code == "ST001":  # ST001's snippet must not open
            continue
        got = {f.code for f in lint(snippet, FAMILY_RULES)}
        assert got == expected[code], f"{snippet.name}: got {sorted(got)}"
        checked += 1
    if not checked:
        pytest.skip("no catalog snippets found")
    assert checked >= len(FAMILY_CODES)
