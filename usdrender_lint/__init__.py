"""usdrender-lint: a validator and linter for OpenUSD usdRender scenes."""

from __future__ import annotations

from importlib import metadata

try:
    __version__ = metadata.version("usdrender-lint")
except metadata.PackageNotFoundError:  # running from a source tree
    __version__ = "0+unknown"

TYPE_CHECKING = False
if TYPE_CHECKING:  # the Python API, for type checkers; imported lazily below
    from .lint_api import lint_file, lint_stage

#: Loaded on first use, so ``import usdrender_lint`` stays cheap (no pxr).
_LAZY = {"lint_file": "lint_api", "lint_stage": "lint_api"}


def __getattr__(name: str):
    if name in _LAZY:
        from importlib import import_module

        return getattr(import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["__version__", "lint_file", "lint_stage"]
