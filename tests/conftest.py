from __future__ import annotations

import os
from pathlib import Path

import pytest

TESTS = Path(__file__).parent
REPO = TESTS.parent
#: ../shared beside the project: present on developer machines and in CI only.
SHARED = Path(os.environ.get("USDRENDER_LINT_SHARED", REPO.parent / "shared"))


@pytest.fixture
def shared_dir() -> Path:
    if not SHARED.is_dir():
        pytest.skip("../shared is not present (only on developer machines and in CI)")
    return SHARED
