"""The benchmark scripts (``benchmarks/`` is a folder of scripts, not a
package), loaded for the tests that generate shots or check the figures."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


def load_script(stem: str) -> ModuleType:
    """``benchmarks/<stem>.py`` as a module (loaded once per test session)."""
    name = f"usdrender_lint_benchmark_{stem}"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, BENCHMARKS / f"{stem}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up while it executes
    spec.loader.exec_module(module)
    return module
