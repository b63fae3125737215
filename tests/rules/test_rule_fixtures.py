"""Every rule fixture folder: pass_*.usda stay silent, fail_*.usda give exactly
the findings they declare (see usdrender_lint.testing)."""

from __future__ import annotations

from pathlib import Path

import pytest

from usdrender_lint.testing import all_rules, check_fixture, fixture_files

FOLDER = Path(__file__).parent
RULES = all_rules()


def _cases():
    for folder in sorted(p for p in FOLDER.iterdir() if p.is_dir() and "_" in p.name):
        code = folder.name.split("_", 1)[0]
        for fixture in fixture_files(folder):
            yield pytest.param(code, fixture, id=f"{folder.name}/{fixture.name}")


@pytest.mark.parametrize(("code", "fixture"), list(_cases()))
def test_fixture(code: str, fixture: Path) -> None:
    check_fixture(fixture, code, RULES)
