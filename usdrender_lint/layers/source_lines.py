"""A text layer's lines as a report shows them, and where a statement of a
line lies: the columns an editor underlines (the language server) and a
terminal report marks (``--format full``) for a finding on that line. No USD
here: the reports read these after the lint."""

from __future__ import annotations

import os

#: Text layers larger than this are not read to show their lines.
MAX_SOURCE_BYTES = 20 * 1024 * 1024


def read_lines(path: str) -> list[str] | None:
    """The lines of the text layer at ``path`` (None: a crate, not UTF-8, too
    large or unreadable: a report shows its findings without source lines)."""
    try:
        if os.path.getsize(path) > MAX_SOURCE_BYTES:
            return None
        with open(path, "rb") as handle:
            data = handle.read()
        if data.startswith(b"PXR-USDC"):
            return None
        # Lines as USD counts them: at "\n" alone (str.splitlines also splits
        # at form feeds and U+2028, which would shift every later line).
        return [line.removesuffix("\r") for line in data.decode("utf-8").split("\n")]
    except (OSError, UnicodeDecodeError):
        return None


def statement_columns(content: str, column: int | None = None) -> tuple[int, int]:
    """The 0-based columns [start, end) of the statement on the line ``content``:
    from its first word to the end of the line, without an opening ``(`` or
    ``{``; from ``column`` (1-based, USD's parse errors give one) on when given.
    At least one character wherever the line has one."""
    end = len(content.rstrip())
    trimmed = content[:end]
    while trimmed.endswith(("(", "{")) and trimmed[:-1].strip():
        trimmed = trimmed[:-1].rstrip()
    end = len(trimmed)
    start = len(content) - len(content.lstrip())
    if column is not None:
        start = min(max(column - 1, 0), len(content))
        end = max(end, start)
    if end == start:  # an empty line, or an error at its end: one character at least
        end = min(start + 1, len(content)) if start < len(content) else start
    return start, end
