"""``--format full``: the text report with each finding's source line under
it and the statement marked, as ruff's ``full`` output and clang-tidy show a
diagnostic's code. Each finding's own line is the text format's, so problem
matchers and quickfix lists read it the same way::

    shots/010/lighting.usda:7: error SE003 /Render/Settings.dataWindowNDC: ...
       |
     7 |         uniform float4 dataWindowNDC = (0.8, 0, 0.2, 1)
       |         ^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^

The line is read from the layer holding the opinion when the report is
written (a crate has none to show; a merged report whose files are elsewhere
shows its findings without them). Tabs are shown as four spaces and other
control characters as one mark each, and the marks are counted in the columns
a terminal gives each character (two for a wide CJK one, none for a combining
mark), so they stay under the statement; a line longer than the terminal (or
200 columns, piped) is cut.
"""

from __future__ import annotations

from ..layers.source_lines import read_lines, statement_columns
from ..model import Finding
from ..paths import columns, fitting, layer_file
from .text import _STYLE, Below, Segment, TextFormatter

#: The widest source line shown when the report is piped.
PIPED_COLUMNS = 200
_GUTTER_STYLE = "blue"
_CUT = "…"


def _shown(content: str) -> str:
    """The line as a terminal shows it: tabs expanded, controls as one mark."""
    content = content.expandtabs(4)
    return "".join(char if char.isprintable() else "\ufffd" for char in content)


class FullFormatter(TextFormatter):
    def below(self, width: int | None) -> Below:
        texts: dict[str, list[str] | None] = {}

        def source(finding: Finding) -> tuple[tuple[Segment, ...], ...]:
            loc = finding.location
            path = layer_file(loc.layer) if loc.line else None
            if path is None or loc.line is None:
                return ()
            key = str(path)
            if key not in texts:
                texts[key] = read_lines(key)
            lines = texts[key]
            if not lines or loc.line > len(lines):
                return ()
            number = str(loc.line)
            gutter = " " * len(number)
            raw = lines[loc.line - 1]
            # Columns counted after the tabs are expanded, as they are shown.
            column = len(raw[: loc.column - 1].expandtabs(4)) + 1 if loc.column else None
            content = _shown(raw)
            start, end = statement_columns(content, column)
            room = max((width or PIPED_COLUMNS) - len(gutter) - 3, 20)
            if columns(content) > room:
                kept = fitting(content, room - 1)
                content = kept + _CUT
                start, end = min(start, len(kept)), min(end, len(kept))
            # Start and end are characters of the line; the marks go in columns.
            lead = " " * columns(content[:start])
            marks = "^" * max(columns(content[start:end]), 1)
            return (
                ((f"{gutter} |", _GUTTER_STYLE),),
                ((f"{number} | ", _GUTTER_STYLE), (content, None)),
                ((f"{gutter} | ", _GUTTER_STYLE), (lead + marks, _STYLE[finding.severity])),
                (),
            )

        return source
