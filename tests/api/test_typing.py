"""mypy passes with the project's own configuration ([tool.mypy] in pyproject.toml)."""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.heavy(seconds=22)

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.skipif(importlib.util.find_spec("mypy") is None, reason="mypy is not installed")
def test_a_plain_mypy_in_the_repository_root_checks_the_package_and_rules_cleanly(
    tmp_path: Path,
) -> None:
    # No targets on the command line: the configuration must name them. Only the
    # cache goes elsewhere, so the run writes nothing into the checkout.
    proc = subprocess.run(
        [sys.executable, "-m", "mypy", "--cache-dir", str(tmp_path)],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    checked = re.search(r"no issues found in (\d+) source files", proc.stdout)
    assert checked, proc.stdout
    sources = [p for top in ("usdrender_lint", "rules") for p in (ROOT / top).rglob("*.py")]
    assert int(checked.group(1)) == len(sources)
