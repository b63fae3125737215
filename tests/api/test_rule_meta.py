"""Meta-tests over the registered rules: metadata, docs, fixtures, catalog."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from usdrender_lint.api import DOC_SECTIONS
from usdrender_lint.api.docs import code_blocks, missing_sections, sections, supporting_layers
from usdrender_lint.profiles import Profiler
from usdrender_lint.registry import build_registry
from usdrender_lint.testing import all_rules, lint_text

REGISTRY = build_registry()
RULE_CLASSES = REGISTRY.rules
FIXTURES = Path(__file__).parents[1] / "rules"
RULES = all_rules()


def test_codes_and_names_are_unique() -> None:
    codes = [r.code for r in RULE_CLASSES]
    names = [r.name for r in RULE_CLASSES]
    assert len(set(codes)) == len(codes)
    assert len(set(names)) == len(names)


@pytest.mark.parametrize("rule", RULE_CLASSES, ids=lambda r: r.code)
def test_rule_has_doc_sections(rule) -> None:
    assert not missing_sections(rule), f"{rule.code} lacks {missing_sections(rule)}"
    assert list(sections(rule))[: len(DOC_SECTIONS)] == list(DOC_SECTIONS)


@pytest.mark.parametrize("rule", RULE_CLASSES, ids=lambda r: r.code)
def test_rule_has_pass_and_fail_fixtures(rule) -> None:
    folders = [p for p in FIXTURES.glob(f"{rule.code}_*") if p.is_dir()]
    assert len(folders) == 1, f"{rule.code}: expected one fixture folder tests/rules/{rule.code}_*"
    folder = folders[0]
    assert folder.name == f"{rule.code}_{rule.name.replace('-', '_')}"
    assert list(folder.glob("pass_*.usda")), f"{folder.name} has no pass_*.usda"
    assert list(folder.glob("fail_*.usda")), f"{folder.name} has no fail_*.usda"


def _doc_cases(section: str):
    for rule in RULE_CLASSES:
        text = sections(rule).get(section, "")
        layers = supporting_layers(text)
        for index, block in enumerate(code_blocks(text)):
            yield pytest.param(rule.code, block, layers, id=f"{rule.code}-{index}")


@pytest.mark.parametrize(("code", "usda", "layers"), list(_doc_cases("Example")))
def test_doc_example_fires(code: str, usda: str, layers: dict) -> None:
    found = lint_text(usda, rules=RULES, layers=layers, name="example.usda", profiler=Profiler())
    assert code in {f.code for f in found}


@pytest.mark.parametrize(("code", "usda", "layers"), list(_doc_cases("Use instead")))
def test_doc_use_instead_is_silent(code: str, usda: str, layers: dict) -> None:
    found = lint_text(
        usda, rules=RULES, layers=layers, name="use_instead.usda", profiler=Profiler()
    )
    assert code not in {f.code for f in found}


def test_every_rule_documents_an_example() -> None:
    lacking = [r.code for r in RULE_CLASSES if not code_blocks(sections(r).get("Example", ""))]
    assert not lacking


_INDEX_ROW = re.compile(r"^\| \[([A-Z]{2}\d{3})\]\([^)]*\) \| `([a-z0-9-]+)`[^|]*\| (\w+) \|")


def test_catalog_index_is_registered(shared_dir: Path) -> None:
    catalog = (shared_dir / "spec" / "rule-catalog.md").read_text(encoding="utf-8")
    rows = [m.groups() for m in map(_INDEX_ROW.match, catalog.splitlines()) if m]
    assert len(rows) == 61
    registered = {r.code: (r.name, r.severity.value) for r in RULE_CLASSES}
    missing = [code for code, _, _ in rows if code not in registered]
    wrong = [
        (code, registered[code], (name, severity))
        for code, name, severity in rows
        if code in registered and registered[code] != (name, severity)
    ]
    assert not wrong, f"registered rules differ from the catalog: {wrong}"
    assert not missing, f"catalog rules not registered yet: {missing}"
