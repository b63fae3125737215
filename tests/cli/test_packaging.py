"""Every package of the source tree is in pyproject's explicit package list:
a subpackage left out installs nowhere, and only a plain install would show it."""

from __future__ import annotations

import tomllib
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def test_every_package_is_listed() -> None:
    setuptools = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(setuptools["packages"])
    found = set()
    for root, name in (
        (REPO / "usdrender_lint", "usdrender_lint"),
        (REPO / "rules", "usdrender_lint.rules"),
    ):
        for init in root.rglob("__init__.py"):
            parts = init.parent.relative_to(root).parts
            if "usdRenderLint" in parts:
                continue  # the plugin module USD imports, mapped to its own top-level name
            found.add(".".join([name, *parts]))
    assert found <= listed, sorted(found - listed)
