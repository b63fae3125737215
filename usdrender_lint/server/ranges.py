"""Places in a document's text: a finding's statement, a spec's line, and the
minimal edits that turn one text into another. Positions are (line, column)
in code points, 0-based; the protocol layer converts columns to the client's units."""

from __future__ import annotations

import difflib
import re
from collections.abc import Iterator

from ..layers.source_lines import statement_columns
from ..records import record


@record(frozen=True)
class Span:
    start: tuple[int, int]
    end: tuple[int, int]


@record(frozen=True)
class Edit:
    """Replace ``span`` of the old text with ``text``."""

    span: Span
    text: str


def statement_span(text: str, line: int | None, column: int | None = None) -> Span:
    """The span of the statement on 1-based ``line`` (from its first word to
    the end of its line, without an opening ``(`` or ``{``); from ``column``
    (1-based, in characters: a parse error's) on when given. The first line when
    ``line`` is None."""
    lines = text.split("\n")
    index = min(max((line or 1) - 1, 0), max(len(lines) - 1, 0))
    content = lines[index] if lines else ""
    start, end = statement_columns(content, column)
    return Span((index, start), (index, end))


def spec_line(text: str, path: str | None, index: dict[str, int] | None = None) -> int | None:
    """The 1-based line that opens the spec of ``path`` in ``text`` or, when
    there is none, that of its nearest ancestor (None: not even a root prim)."""
    if not path:
        return None
    from ..layers.usda_text import index_usda

    lines = index if index is not None else index_usda(text)
    candidate = path
    while candidate and candidate != "/":
        if candidate in lines:
            return lines[candidate]
        cut = max(candidate.rfind("/"), candidate.rfind("."))
        candidate = candidate[:cut]
    return None


def _position(text: str, offset: int, starts: list[int]) -> tuple[int, int]:
    import bisect

    line = bisect.bisect_right(starts, offset) - 1
    return (line, offset - starts[line])


def lines_of(text: str) -> list[str]:
    """The text's lines as the spans here count them, each with its end: split
    at ``\n`` only (``str.splitlines`` also splits at a form feed, U+2028, ...,
    which a layer's comment may hold and no editor ends a line at)."""
    parts = text.split("\n")
    return [part + "\n" for part in parts[:-1]] + [parts[-1]]


#: Where the protocol ends a line (LSP 3.17, "Text Documents": \n, \r\n or \r).
_LINE_END = re.compile(r"\r\n|\r|\n")
#: The other characters ``str.splitlines`` ends a line at.
_PYTHON_LINE_END = re.compile("[\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029]")


def editor_lines(text: str) -> list[str]:
    """The text's lines as the editor numbers them in the positions of its
    edits, each with its end: the protocol's line ends only, not the form
    feed, U+2028, ... that ``str.splitlines`` also splits at."""
    if _PYTHON_LINE_END.search(text) is None:
        # Several times faster on a large document, which each edit splits.
        lines = text.splitlines(keepends=True)
        if not lines or lines[-1].endswith(("\n", "\r")):
            lines.append("")
        return lines
    lines = []
    start = 0
    for end in _LINE_END.finditer(text):
        lines.append(text[start : end.end()])
        start = end.end()
    lines.append(text[start:])
    return lines


def _line_starts(text: str) -> list[int]:
    starts = [0]
    starts.extend(i + 1 for i, char in enumerate(text) if char == "\n")
    return starts


def text_edits(old: str, new: str) -> list[Edit]:
    """Edits that turn ``old`` into ``new``, each as small as the texts allow:
    the changed lines, less the characters they share at either end."""
    old_lines = old.splitlines(keepends=True)
    new_lines = new.splitlines(keepends=True)
    old_starts = _line_starts(old)
    offsets = [0]
    for line in old_lines:
        offsets.append(offsets[-1] + len(line))
    edits = []
    matcher = difflib.SequenceMatcher(None, old_lines, new_lines, autojunk=False)
    for tag, i1, i2, j1, j2 in matcher.get_opcodes():
        if tag == "equal":
            continue
        start, end = offsets[i1], offsets[i2]
        before, after = old[start:end], "".join(new_lines[j1:j2])
        for cut_start, cut_end, replacement in _trim(before, after):
            edits.append(
                Edit(
                    Span(
                        _position(old, start + cut_start, old_starts),
                        _position(old, start + cut_end, old_starts),
                    ),
                    replacement,
                )
            )
    return edits


def _trim(before: str, after: str) -> Iterator[tuple[int, int, str]]:
    prefix = 0
    limit = min(len(before), len(after))
    while prefix < limit and before[prefix] == after[prefix]:
        prefix += 1
    suffix = 0
    while (
        suffix < limit - prefix
        and before[len(before) - 1 - suffix] == after[len(after) - 1 - suffix]
    ):
        suffix += 1
    yield prefix, len(before) - suffix, after[prefix : len(after) - suffix]


def apply_edits(text: str, edits: list[Edit]) -> str:
    """``text`` with ``edits`` (of non-overlapping spans) applied."""
    starts = _line_starts(text)

    def offset(position: tuple[int, int]) -> int:
        line, column = position
        if line >= len(starts):
            return len(text)
        return starts[line] + column

    result = text
    for edit in sorted(edits, key=lambda e: e.span.start, reverse=True):
        result = result[: offset(edit.span.start)] + edit.text + result[offset(edit.span.end) :]
    return result
