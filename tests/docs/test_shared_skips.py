"""A plain clone's test run ends by saying how many tests skipped for want of
../shared (tests/conftest.py)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.heavy(seconds=13)

REPO = Path(__file__).resolve().parents[2]


def _run(shared: str) -> str:
    env = {**os.environ, "USDRENDER_LINT_SHARED": shared}
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "tests/engine/test_corpus.py",
        ],
        cwd=REPO,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    return run.stdout


def test_a_plain_clone_says_how_many_tests_need_shared(tmp_path: Path) -> None:
    lines = _run(str(tmp_path / "absent")).strip().splitlines()
    # The line just above pytest's closing one, with the count pytest gives.
    assert lines[-2].startswith("1 test skipped for want of ../shared"), lines[-3:]
    assert "docs/contributing.md" in lines[-2]
    assert lines[-1].startswith("1 skipped")
