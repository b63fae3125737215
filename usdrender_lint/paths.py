"""How paths are shown: relative to the working directory when below it, and
the file on disk behind a layer identifier (no pxr)."""

from __future__ import annotations

from pathlib import Path


def layer_file(identifier: str | None) -> Path | None:
    """The file on disk behind a layer identifier: a layer inside a ``.usdz``
    (``pkg.usdz[inner.usda]``) is the package; anonymous layers have none."""
    if not identifier or identifier.startswith("anon:"):
        return None
    if identifier.endswith("]") and "[" in identifier:
        identifier = identifier[: identifier.index("[")]
    return Path(identifier).resolve()


def display_path(path: str | None) -> str:
    """A path relative to the working directory when it is below it."""
    if not path:
        return ""
    try:
        return str(Path(path).resolve().relative_to(Path.cwd().resolve()))
    except (ValueError, OSError):
        return path
