"""The human format: one line per finding, its location first.

``path:line:col: severity CODE prim-path: message``, the way compilers write
them, so a terminal, VS Code's problem matchers, vim's quickfix and emacs'
compile mode jump to the opinion (``examples/usdrender-lint-problem-matcher.json``
reads it in GitHub Actions). The path is the layer holding the opinion. Lines
are sorted by path, line, then code. On a terminal the message wraps at words
to its width (the location never does) and rich colours it, with no style at
all when ``NO_COLOR`` is set; piped output keeps one plain line per finding
and pays neither rich's import nor its escapes (unless ``FORCE_COLOR`` asks
for the colours).
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Iterable
from typing import TextIO

from ..model import AppliedFix, FileResult, Finding, FixInfo, Report, Severity
from ..paths import columns, display_path, layer_file, printable
from ..records import record
from . import HELD_BY_BASELINE, FormatOptions, shown_fix, statistics_lines

_STYLE = {Severity.ERROR: "bold red", Severity.WARNING: "yellow", Severity.INFO: "cyan"}
#: Continuation lines of a wrapped message start here.
INDENT = "    "
#: USD's parse errors begin with the position the location already gives.
#: (Pattern text: re compiles it at first use, not at every start-up.)
_POSITION = r"^.+?:(\d+)(?::(\d+))?: "

#: A piece of text and its rich style (None: plain).
Segment = tuple[str, "str | None"]
#: A line is a list of segments.
Line = list[Segment]


@record(frozen=True)
class Entry:
    """One report line before layout: the location, then the rest."""

    sort_key: tuple
    location: str
    head: tuple[Segment, ...]
    message: tuple[Segment, ...]
    #: Lines shown under it (``--format full``: the source line).
    below: tuple[tuple[Segment, ...], ...] = ()


def _plural(count: int, word: str, plural: str | None = None) -> str:
    return f"{count} {word}" if count == 1 else f"{count} {plural or word + 's'}"


def _is_terminal(stream: TextIO) -> bool:
    isatty = getattr(stream, "isatty", None)
    return bool(isatty and isatty())


def _no_color() -> bool:
    # https://no-color.org: present and not empty.
    return os.environ.get("NO_COLOR", "") != ""


def _force_color() -> bool:
    """Colour piped output too, as ruff and eslint do for CI logs: FORCE_COLOR
    (https://force-color.org, not empty) or CLICOLOR_FORCE (not "0")."""
    forced = os.environ.get("CLICOLOR_FORCE", "0") not in ("", "0")
    return forced or os.environ.get("FORCE_COLOR", "") != ""


def _file_of(identifier: str | None, fallback: str) -> str:
    """The file a location names, as the user would type it."""
    on_disk = layer_file(identifier)
    return printable(display_path(str(on_disk)) if on_disk else display_path(fallback) or fallback)


def terminal_width(stream: TextIO) -> int | None:
    """The width to wrap at: the terminal's, or None when piped."""
    if not _is_terminal(stream):
        return None
    from rich.console import Console

    console = Console(file=stream)
    if not console.is_dumb_terminal:
        return console.width
    # rich gives TERM=dumb (an editor's shell or compilation buffer) 80 columns
    # whatever its size or COLUMNS (rich/console.py, Console.size): take
    # COLUMNS, else the terminal's own size, else wrap nothing (the display does).
    import shutil

    return shutil.get_terminal_size((0, 0)).columns or None


def write_lines(lines: Iterable[Line], stream: TextIO) -> None:
    """Styled lines through rich on a terminal or when colour is forced (not
    even bold or dim with NO_COLOR, which wins); plain text otherwise."""
    forced = _force_color()
    if not (forced or _is_terminal(stream)) or _no_color():
        for line in lines:
            stream.write("".join(text for text, _ in line) + "\n")
        return
    from rich.console import Console
    from rich.text import Text

    # force_terminal: rich itself would not colour CLICOLOR_FORCE's pipe.
    console = Console(file=stream, soft_wrap=True, highlight=False, force_terminal=forced or None)
    for line in lines:
        console.print(Text.assemble(*((text, style or "") for text, style in _merged(line))))


#: What a report shows under a finding's line (``--format full``: its source).
Below = Callable[[Finding], tuple[tuple[Segment, ...], ...]]


def finding_entry(
    finding: Finding,
    show_profile: bool = False,
    below: Below | None = None,
    shown: tuple[FixInfo, bool] | None = None,
) -> Entry:
    loc = finding.location
    file = _file_of(loc.layer, loc.file)
    line = loc.line if loc.layer and layer_file(loc.layer) else None
    column = loc.column if line else None
    where = file + (f":{line}" if line else "") + (f":{column}" if column else "") + ":"
    message = _without_position(printable(finding.message), line)
    label = (finding.severity.value, _STYLE[finding.severity])
    head, tail = _labelled(label, finding.code, loc.path, message)
    if shown is not None:  # formatters.shown_fix
        fix, held = shown
        kind = "fix" if fix.safe else "unsafe fix"
        if held:
            kind += f", {HELD_BY_BASELINE}"
        tail.append((f"[{kind}: {printable(fix.description)}]", "dim"))
    if show_profile and finding.profile:
        tail.append((f"[profile {finding.profile}: {finding.profile_reason}]", "dim"))
    linted = printable(display_path(loc.file) or loc.file)
    if linted != file:
        tail.append((f"(stage {linted})", "dim"))
    key = (file, line or 0, column or 0, finding.code, linted, message)
    return Entry(key, where, tuple(head), tuple(tail), below(finding) if below else ())


def _without_position(message: str, line: int | None) -> str:
    """The message without a leading position that repeats the entry's line."""
    matched = re.match(_POSITION, message)
    if matched and line and int(matched.group(1)) == line:
        return message[matched.end() :]
    return message


def _labelled(
    label: Segment, code: str, path: str | None, message: str
) -> tuple[list[Segment], list[Segment]]:
    """An entry's head (``label`` and the code) and its message, which the prim
    path starts (it may wrap, as the message does)."""
    head: list[Segment] = [label]
    tail: list[Segment] = [(message, None)]
    if path:
        head.append((code, "bold"))
        tail.insert(0, (printable(path) + ":", None))
    else:
        head.append((code + ":", "bold"))
    return head, tail


def error_entry(result: FileResult) -> Entry:
    file = printable(display_path(result.file) or result.file)
    reason = printable(result.error or "could not be linted")
    for prefix in (f"{printable(result.file)}: ", f"{file}: "):
        if reason.startswith(prefix):
            reason = reason[len(prefix) :]
            break
    return Entry((file, 0, 0, ""), file + ":", (("error:", "bold red"),), ((reason, None),))


def fix_entry(fix: AppliedFix, dry_run: bool = False) -> Entry:
    file = _file_of(fix.layer, fix.file)
    label = "would fix" if dry_run else "fixed"  # --diff writes nothing
    head, tail = _labelled((label, "green"), fix.code, fix.path, printable(fix.description))
    return Entry((file, fix.code), file + ":", tuple(head), tuple(tail))


def wrap(entry: Entry, width: int | None) -> list[list[Segment]]:
    """The entry's physical lines: the location whole on the first, then the
    message. With a ``width`` its words fill lines up to it, continuing on
    lines indented by INDENT (a word longer than a line is not cut); without
    one it is a single line, the message as it is."""
    first: list[Segment] = [(entry.location, "bold")]
    for text, style in entry.head:
        first += [(" ", None), (text, style)]
    lines = [first]
    if width is None:
        for text, style in entry.message:
            first += [(" ", None), (text, style)]
        return lines
    # Counted in terminal columns: a wide CJK character takes two.
    used = sum(columns(text) for text, _ in first)
    fresh = False  # the last line holds only the indent
    for text, style in entry.message:
        for word in text.split():
            size = columns(word)
            if not fresh and used + 1 + size > width:
                lines.append([(INDENT, None)])
                used, fresh = len(INDENT), True
            if fresh:
                lines[-1].append((word, style))
                used += size
                fresh = False
            else:
                lines[-1] += [(" ", None), (word, style)]
                used += 1 + size
    return lines


def _merged(line: list[Segment]) -> list[Segment]:
    """Neighbouring segments of one style (a space between two words of it
    included) as one, so a styled phrase costs one escape sequence."""
    merged: list[Segment] = []
    for index, (text, style) in enumerate(line):
        between = 0 < index < len(line) - 1 and line[index - 1][1] == line[index + 1][1]
        if text == " " and style is None and between:
            style = line[index - 1][1]
        if merged and merged[-1][1] == style:
            merged[-1] = (merged[-1][0] + text, style)
        else:
            merged.append((text, style))
    return merged


class TextFormatter:
    #: It never reads Report.rules nor the configuration digest, so the
    #: command does not build them.
    reads_rules = False
    reads_configuration = False

    def render(self, report: Report, stream: TextIO, options: FormatOptions) -> None:
        width = terminal_width(stream)
        entries, summary = self._entries(report, options, self.below(width))
        lines: list[Line] = []
        for entry in entries:
            lines += wrap(entry, width)
            lines += [list(line) for line in entry.below]
        for text in summary:
            if width:
                import textwrap  # only for a terminal: its import compiles patterns

                # Whole words, as the findings wrap: "--unsafe-fixes" cut at its
                # hyphen could not be copied back into a command.
                parts = textwrap.wrap(
                    text,
                    width,
                    subsequent_indent=INDENT,
                    break_on_hyphens=False,
                    break_long_words=False,
                )
            else:
                parts = [text]
            lines.extend([(part, None)] for part in parts)
        write_lines(lines, stream)

    def below(self, width: int | None) -> Below | None:
        """What to show under each finding's line (the full format's source)."""
        return None

    def _entries(
        self, report: Report, options: FormatOptions, below: Below | None = None
    ) -> tuple[list[Entry], list[str]]:
        shown = [
            finding
            for finding in report.findings
            if options.show_info or finding.severity != Severity.INFO
        ]
        entries = [
            finding_entry(finding, options.show_info, below, shown_fix(report, finding))
            for finding in shown
        ]
        entries += [error_entry(result) for result in report.errored_files]
        entries.sort(key=lambda entry: entry.sort_key)
        if options.quiet:  # --quiet: what is wrong, and nothing about it
            return entries, statistics_lines(report) if options.statistics else []
        fixes = sorted(
            (fix_entry(fix, options.dry_run) for fix in report.applied_fixes),
            key=lambda e: e.sort_key,
        )
        summary = [self._summary(report, len(report.findings) - len(shown), options)]
        if options.statistics:
            summary += statistics_lines(report)
        return entries + fixes, summary

    @staticmethod
    def _summary(report: Report, hidden: int, options: FormatOptions) -> str:
        counts = report.by_severity()
        errors = len(report.errored_files)
        text = (
            f"{_plural(len(report.findings) - hidden, 'finding')} in "
            f"{_plural(len(report.files), 'file')}: "
            f"{_plural(counts['error'], 'error')}, {_plural(counts['warning'], 'warning')}"
        )
        # Only info findings are hidden: the count says what is shown, then what is not.
        if hidden:
            text += f" ({hidden} info hidden; --show-info shows them)"
        else:
            text += f", {counts['info']} info"
        if errors:
            text += f"; {_plural(errors, 'file')} could not be linted"
        if not options.fixing:
            # --fix fixes hidden info findings too: the count says how many it holds.
            hidden_fixable = report.fixable(Severity.INFO)[0] if hidden else 0
            text += "".join(_fixable(*report.fixable(), hidden_fixable))
        if report.applied_fixes:
            verb = "would be applied" if options.dry_run else "applied"
            text += f"; {_plural(len(report.applied_fixes), 'fix', 'fixes')} {verb}"
        if report.unapplied_fixes:
            text += f"; {_plural(len(report.unapplied_fixes), 'fix', 'fixes')} not applied"
        return text + "."


def _fixable(safe: int, unsafe: int, hidden: int = 0) -> Iterable[str]:
    if safe:
        yield f"; {safe} fixable with --fix"
    if hidden:
        yield f", {hidden} of them hidden info"
    if unsafe:
        yield (
            f" ({unsafe} more with --unsafe-fixes)"
            if safe
            else (f"; {unsafe} fixable with --fix --unsafe-fixes")
        )
