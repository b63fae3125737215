"""usdrender-lint: a validator and linter for OpenUSD usdRender scenes."""

from __future__ import annotations

#: The one place the version is written (pyproject.toml reads it from here), so
#: start-up needs no importlib.metadata.
__version__ = "0.6.1"


TYPE_CHECKING = False
if TYPE_CHECKING:  # the Python API, for type checkers; imported lazily below
    from .running.python_api import SchemaRegistryError, lint_file, lint_stage

#: Loaded on first use, so ``import usdrender_lint`` stays cheap (no pxr).
_LAZY = {
    "lint_file": "running.python_api",
    "lint_stage": "running.python_api",
    "SchemaRegistryError": "running.python_api",
}


def __getattr__(name: str):
    if name in _LAZY:
        from importlib import import_module

        return getattr(import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["SchemaRegistryError", "__version__", "lint_file", "lint_stage"]
