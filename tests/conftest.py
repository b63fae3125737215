from __future__ import annotations

import os
from pathlib import Path

import pytest

TESTS = Path(__file__).parent
REPO = TESTS.parent
#: ../shared beside the project: present on developer machines and in CI only.
SHARED = Path(os.environ.get("USDRENDER_LINT_SHARED", REPO.parent / "shared"))


@pytest.fixture(autouse=True)
def _no_result_cache(monkeypatch: pytest.MonkeyPatch) -> None:
    """Tests lint with a fresh engine every time (tests/running/test_result_cache.py
    turns the cache on for itself): a result reused from an earlier test would
    hide what a test changed in the engine or its rules."""
    monkeypatch.setenv("USDRENDER_LINT_NO_CACHE", "1")


@pytest.fixture
def shared_dir() -> Path:
    if not SHARED.is_dir():
        pytest.skip("../shared is not present (only on developer machines and in CI)")
    return SHARED
