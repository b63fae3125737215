"""usdrender-lint: a validator and linter for OpenUSD usdRender scenes."""

from __future__ import annotations

from importlib import metadata

try:
    __version__ = metadata.version("usdrender-lint")
except metadata.PackageNotFoundError:  # running from a source tree
    __version__ = "0+unknown"
