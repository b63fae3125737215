"""``--diff`` output: a patch that ``git apply`` and ``patch -p1`` accept.

One unified diff per changed text layer, named relative to the current
directory (``a/shots/shot.usda``), with ``\\ No newline at end of file`` after a
last line without one. Neither tool applies a path outside the current
directory (``../``), so such a layer gets no diff: :func:`patch` returns None
and the caller says so.
"""

from __future__ import annotations

import difflib
import os

NO_NEWLINE = "\\ No newline at end of file\n"


def patch_name(path: str, cwd: str | None = None) -> str | None:
    """``path`` relative to the current directory with ``/`` separators, or None
    when it is outside it."""
    cwd = os.path.realpath(cwd or os.getcwd())
    real = os.path.realpath(path)
    try:
        relative = os.path.relpath(real, cwd)
    except ValueError:  # another drive (Windows)
        return None
    if relative == os.pardir or relative.startswith(os.pardir + os.sep):
        return None
    return relative.replace(os.sep, "/")


def patch(path: str, old: str, new: str, cwd: str | None = None) -> str | None:
    """The unified diff from ``old`` to ``new`` for the file at ``path`` (None
    outside the current directory; empty when nothing changed)."""
    name = patch_name(path, cwd)
    if name is None:
        return None
    out = []
    lines = difflib.unified_diff(
        _lines(old),
        _lines(new),
        fromfile=f"a/{name}",
        tofile=f"b/{name}",
    )
    for line in lines:
        out.append(line)
        if not line.endswith("\n"):
            out.append("\n" + NO_NEWLINE)
    return "".join(out)


def _lines(text: str) -> list[str]:
    """Lines as the patch tools count them: split at ``\\n`` only (``splitlines``
    would also split at form feeds and Unicode line separators)."""
    parts = text.split("\n")
    lines = [part + "\n" for part in parts[:-1]]
    if parts[-1]:
        lines.append(parts[-1])
    return lines
