"""Every rule fixture folder: pass_*.usda stay silent, fail_*.usda give exactly
the findings they declare, each expect line in full (see usdrender_lint.testing)."""

from __future__ import annotations

from pathlib import Path

import pytest

from usdrender_lint.profiles import Profiler
from usdrender_lint.testing import all_rules, check_fixture, expectations, fixture_files, lint

pytestmark = pytest.mark.heavy(seconds=17)

FOLDER = Path(__file__).parent
RULES = all_rules()


def _cases():
    for folder in sorted(p for p in FOLDER.iterdir() if p.is_dir() and "_" in p.name):
        code = folder.name.split("_", 1)[0]
        for fixture in fixture_files(folder):
            yield pytest.param(code, fixture, id=f"{folder.name}/{fixture.name}")


@pytest.mark.parametrize(("code", "fixture"), list(_cases()))
def test_fixture(code: str, fixture: Path) -> None:
    # Under auto, as `check` lints: every fixture holds with profiles (R2-5).
    check_fixture(fixture, code, RULES, Profiler())


def _fail_fixtures():
    for folder in sorted(p for p in FOLDER.iterdir() if p.is_dir() and "_" in p.name):
        for fixture in fixture_files(folder):
            if fixture.name.startswith("fail_"):
                yield pytest.param(fixture, id=f"{folder.name}/{fixture.name}")


@pytest.mark.parametrize("fixture", list(_fail_fixtures()))
def test_fail_fixture_states_count_fix_and_fragment(fixture: Path) -> None:
    short = [f"line {e.line}: {e}" for e in expectations(fixture) if not e.full]
    assert not short, (
        f"{fixture.name}: write every expect line in full, "
        f"'# expect: CODE <path> xN fix|nofix \"message fragment\"': {short}"
    )


def test_pass_fixtures_declare_nothing() -> None:
    declaring = [
        str(fixture.relative_to(FOLDER))
        for folder in FOLDER.iterdir()
        if folder.is_dir()
        for fixture in fixture_files(folder)
        if fixture.name.startswith("pass_") and expectations(fixture)
    ]
    assert not declaring, f"pass fixtures with expect lines: {declaring}"


def _opening_fixtures():
    for folder in sorted(p for p in FOLDER.iterdir() if p.is_dir() and "_" in p.name):
        if not folder.name.startswith("ST001_"):  # ST001's fixtures fail to open on purpose
            for fixture in fixture_files(folder):
                yield pytest.param(fixture, id=f"{folder.name}/{fixture.name}")


@pytest.mark.parametrize("fixture", list(_opening_fixtures()))
def test_fixture_opens(fixture: Path) -> None:
    # A fixture USD cannot open gives only ST001: a pass fixture then passes
    # whatever its rule does, and checks nothing.
    st001 = [rule for rule in RULES if rule.code == "ST001"]
    found = [f.message for f in lint(fixture, st001)]
    assert not found, f"{fixture.name} does not open: {found}"
