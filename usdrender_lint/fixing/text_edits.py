"""A fix's change to a text layer, written into the file's own text.

A fix edits a layer through Sdf. Saving that layer with Sdf would rewrite the
whole file the way Sdf writes layers (properties sorted, comments dropped,
numbers respelled), so instead the change is found and spliced into the text:
the layer's text ``T`` is read as Sdf exported it before the fix (``O``) and
after (``N``). The three texts are read block by block with the same statement
parser (``layers.usda_text.statements``), statements pair up by key, and only
where ``O`` and ``N`` differ does the edit reach into ``T``: a changed word of a
head, a value (an array element by element), a metadata entry, a dictionary
entry, a whole statement added or removed. Everything else in ``T`` keeps its
bytes: order, indentation, spelling, blank lines, comments.

New text follows the file's indentation and line ends. The result is checked:
Sdf must read it as exactly ``N``; if not (or when a change cannot be placed)
:class:`CannotEdit` says why, and the fix is not applied.
"""

from __future__ import annotations

import difflib
import re
from collections import Counter, defaultdict
from dataclasses import dataclass, field

from pxr import Sdf, Tf

from ..layers.usda_text import (
    BODY,
    DICT,
    META,
    VARIANTS,
    Statement,
    element_gap,
    element_spans,
    layer_text,
    statements,
)

#: Sdf writes four spaces per level.
_SDF_INDENT = "    "
_TRIPLE_STRING = re.compile(r'""".*?"""|' r"'''.*?'''", re.DOTALL)
_SPACES = re.compile(r"[ \t\r\f\v]*")
#: The indentation of each line with something on it.
_LINE_INDENT = re.compile(r"^([ \t]*)\S", re.MULTILINE)
_BOOL_WORD = re.compile(r"\bbool(?:\[\])?\s+[\w:]+\s*=\s*\[?\s*(?:true|false)\b")
_BOOL_DIGIT = re.compile(r"(?<![\w.])[01](?![\w.])")


class CannotEdit(Exception):
    """The change cannot be written as an edit of the text (one line: why)."""


def canonical(text: str) -> str | None:
    """``text`` as Sdf exports it after reading it (None when Sdf cannot read it)."""
    layer = Sdf.Layer.CreateAnonymous(".usda")
    with Tf.DiagnosticTrap() as trap:
        try:
            ok = layer.ImportFromString(text)
        except Tf.ErrorException:
            ok = False
        trap.Clear()
    return layer.ExportToString() if ok else None


def edit_text(original: str, before: str, after: str) -> str:
    """``original`` (a layer's text, which Sdf exports as ``before``) with only
    the edits that make Sdf export it as ``after``. Raises :class:`CannotEdit`."""
    if before == after:
        return original
    editor = _Editor(original, before, after)
    editor.layer()
    text = editor.result()
    if canonical(text) != after:
        raise CannotEdit("the edited text would not read back as the fixed layer")
    return text


def indent_unit(text: str) -> str:
    """The file's indentation step: the commonest increase of indentation from
    one line to the next (a tab when lines are indented with tabs)."""
    steps: Counter[str] = Counter()
    previous = ""
    for match in _LINE_INDENT.finditer(text, 0, 200_000):
        indent = match.group(1)
        if len(indent) > len(previous) and indent.startswith(previous):
            steps[indent[len(previous) :]] += 1
        previous = indent
    if not steps:
        return _SDF_INDENT
    return max(steps, key=lambda step: (steps[step], -len(step)))


# -- the editor ---------------------------------------------------------------------


@dataclass(order=True)
class _Edit:
    start: int
    end: int
    seq: int
    text: str = field(compare=False)


@dataclass
class _Freed:
    """The place of a removed statement: on its own line, or (``inline``) before
    the comment that ends its line."""

    kind: str
    position: int
    edit: _Edit
    inline: bool


@dataclass
class _Insertion:
    """A prim to add, placed once the removed prims (moves) are all known."""

    statement: Statement
    position: int
    indent: str
    before: str  # text before the prim's first line (a line end, a blank line)
    after: str


class _Editor:
    def __init__(self, t: str, o: str, n: str) -> None:
        self.t, self.o, self.n = t, o, n
        self.edits: list[_Edit] = []
        self.unit = indent_unit(t)
        #: The line end most lines have (one line pasted from elsewhere does not count).
        self.newline = "\r\n" if t.count("\r\n") * 2 > t.count("\n") else "\n"
        #: New bool values are spelt as the file spells them (Sdf writes 1 and 0).
        self.bool_words = _BOOL_WORD.search(t) is not None
        #: Removed prims by name, for a prim the fix moved (ST008).
        self.removed: dict[str, list[tuple[Statement, Statement]]] = defaultdict(list)
        self.insertions: list[_Insertion] = []
        #: Line ends that close a one-line bracket pair opened for new statements.
        self.closings: list[tuple[int, str]] = []

    # -- edits ---------------------------------------------------------------------

    def replace(self, start: int, end: int, text: str) -> None:
        self.edits.append(_Edit(start, end, len(self.edits), text))

    def result(self) -> str:
        for insertion in self.insertions:
            body = self.added_text(insertion.statement, insertion.indent)
            self.replace(
                insertion.position,
                insertion.position,
                insertion.before + insertion.indent + body + insertion.after,
            )
        for position, text in self.closings:
            self.replace(position, position, text)
        return apply_edits(self.t, self.edits)

    # -- text helpers ----------------------------------------------------------------

    @staticmethod
    def line_start(text: str, pos: int) -> int:
        return text.rfind("\n", 0, pos) + 1

    def indent(self, text: str, pos: int) -> str:
        start = self.line_start(text, pos)
        return text[start : _past_spaces(text, start)].replace("\r", "")

    def starts_line(self, pos: int) -> bool:
        start = self.line_start(self.t, pos)
        return self.t[start:pos].strip() == ""

    def same(self, o: Statement | tuple[int, int] | None, n: Statement | tuple[int, int] | None):
        return self.normal(self.o, o) == self.normal(self.n, n)

    def normal(self, text: str, part: Statement | tuple[int, int] | None) -> str | None:
        """A statement or part as text, its continuation lines without its indentation
        (a moved prim compares equal at any depth)."""
        if part is None:
            return None
        start, end = (part.start, part.end) if isinstance(part, Statement) else part
        indent = self.indent(text, start)
        chunk = text[start:end]
        return chunk.replace("\n" + indent, "\n") if indent else chunk

    def render(self, start: int, end: int, indent: str) -> str:
        """Sdf's text of ``N[start:end]`` in the file's style, its first line at ``indent``."""
        return _reindent(
            self.n[start:end], self.indent(self.n, start), indent, self.unit, self.newline
        )

    def render_value(self, statement: Statement, start: int, end: int, indent: str) -> str:
        text = self.render(start, end, indent)
        if self.bool_words and any(self.n[a:b] in ("bool", "bool[]") for a, b in statement.words):
            text = _BOOL_DIGIT.sub(lambda m: "true" if m.group() == "1" else "false", text)
        return text

    def render_statement(self, n: Statement, indent: str) -> str:
        """A whole new statement in the file's style."""
        if n.value is None:
            return self.render(n.start, n.end, indent)
        return (
            self.render(n.start, n.value[0], indent)
            + self.render_value(n, *n.value, indent)
            + self.render(n.value[1], n.end, indent)
        )

    # -- the layer ---------------------------------------------------------------------

    def layer(self) -> None:
        t, o, n = layer_text(self.t), layer_text(self.o), layer_text(self.n)
        if not self.same(o.meta, n.meta):
            if t.meta is not None and n.meta is not None:
                self.group(META, _inner(t.meta), _inner(o.meta), _inner(n.meta), t.meta[0])
            elif n.meta is not None:
                lead = "" if self.t[: t.header_end].endswith("\n") else self.newline
                text = self.render(*n.meta, "")
                self.replace(t.header_end, t.header_end, lead + text + self.newline)
            elif t.meta is not None:
                self.delete_lines(t.meta[0], t.meta[1])
        self.group(BODY, t.body, o.body, n.body, None)

    # -- one block ---------------------------------------------------------------------

    def group(
        self,
        context: str,
        t_span: tuple[int, int],
        o_span: tuple[int, int],
        n_span: tuple[int, int],
        opener: int | None,
    ) -> None:
        """Edit the statements between ``t_span`` (``opener``: the offset of its
        bracket, None at the top of the layer) so they read as ``n_span``."""
        ts = statements(self.t, *t_span, context)
        os_ = statements(self.o, *o_span, context)
        ns = statements(self.n, *n_span, context)
        by_key: dict[tuple[str, ...], list[Statement]] = defaultdict(list)
        for statement in ts:
            by_key[statement.key].append(statement)
        old = {s.key: s for s in os_}
        new = {s.key: s for s in ns}
        for n in ns:
            o = old.get(n.key)
            if o is not None and not self.same(o, n):
                self.statement(self.find(by_key, n.key)[-1], o, n, context)
        freed = self.remove_gone(os_, new, by_key, context)
        added = [n for n in ns if n.key not in old]
        if added:
            kept = [s for s in ts if s.key in old and s.key in new]
            _Placer(self, context, ts, kept, by_key, ns, freed, t_span, opener).place(added)

    def remove_gone(
        self,
        os_: list[Statement],
        new: dict[tuple[str, ...], Statement],
        by_key: dict,
        context: str,
    ) -> list[_Freed]:
        """Delete the statements the new text no longer has; returns where removed
        statements' lines were: a new statement of the same kind takes the place
        (a replaced line, not a line removed and one added)."""
        freed: list[_Freed] = []
        for o in os_:
            if o.key in new:
                continue
            found = self.find(by_key, o.key)
            for t in found:
                slot = self.delete(t, context)
                if slot is not None and t.kind != "prim":
                    freed.append(slot)
            if o.kind == "prim":
                self.removed[o.key[1]].append((found[-1], o))
        return freed

    def find(self, by_key: dict, key: tuple[str, ...]) -> list[Statement]:
        found = by_key.get(key)
        if not found:
            raise CannotEdit(f"the text has no statement for {_describe(key)} where Sdf has one")
        return found

    def statement(self, t: Statement, o: Statement, n: Statement, context: str) -> None:
        """Edit statement ``t`` (which reads as ``o``) so that it reads as ``n``."""
        if not (t.kind == o.kind == n.kind):
            self.replace(t.start, t.end, self.render(n.start, n.end, self.indent(self.t, t.start)))
            return
        self.head(t, o, n)
        if not self.same(o.value, n.value):
            self.value(t, o, n)
        if not self.same(o.meta, n.meta):
            self.meta(t, o, n)
        if not self.same(o.body, n.body):
            if t.body is None or o.body is None or n.body is None:
                raise CannotEdit(f"the body of {_describe(t.key)} cannot be edited")
            self.group(BODY, _inner(t.body), _inner(o.body), _inner(n.body), t.body[0])

    def head(self, t: Statement, o: Statement, n: Statement) -> None:
        old = [self.o[a:b] for a, b in o.words]
        new = [self.n[a:b] for a, b in n.words]
        if old == new:
            return
        if not t.words:
            raise CannotEdit(f"the head of {_describe(t.key)} cannot be edited")
        if len(old) == len(new) == len(t.words):
            for (start, end), before, after in zip(t.words, old, new, strict=True):
                if before != after:
                    self.replace(start, end, after)
        else:
            self.replace(t.words[0][0], t.words[-1][1], " ".join(new))

    def value(self, t: Statement, o: Statement, n: Statement) -> None:
        if n.value is None:
            if t.value is not None:
                self.replace(t.head_end, t.value[1], "")
            return
        indent = self.indent(self.t, t.start)
        if t.value is None:
            self.replace(t.head_end, t.head_end, " = " + self.render_value(n, *n.value, indent))
            return
        assert o.value is not None
        first = {self.t[t.value[0]], self.o[o.value[0]], self.n[n.value[0]]}
        if t.kind == "variantSet" and first == {"{"}:
            self.group(VARIANTS, _inner(t.value), _inner(o.value), _inner(n.value), t.value[0])
        elif first == {"{"} and self.holds_dictionary(t):
            self.group(DICT, _inner(t.value), _inner(o.value), _inner(n.value), t.value[0])
        elif len(first) == 1 and first <= {"[", "("} and t.key[-1] != "timeSamples":
            self.elements(t.value, o.value, n.value)
        else:
            self.replace(*t.value, self.render_value(n, *n.value, indent))

    def holds_dictionary(self, t: Statement) -> bool:
        if t.kind == "entry":
            return True
        return t.kind == "property" and any(self.t[a:b] == "dictionary" for a, b in t.words)

    def elements(
        self, t_span: tuple[int, int], o_span: tuple[int, int], n_span: tuple[int, int]
    ) -> None:
        """Edit an array or tuple element by element (the others keep their spelling)."""
        ts = element_spans(self.t, t_span)
        os_ = element_spans(self.o, o_span)
        ns = element_spans(self.n, n_span)
        if len(ts) != len(os_):
            self.replace(*t_span, self.render(*n_span, self.indent(self.t, t_span[0])))
            return
        old = [self.o[a:b] for a, b in os_]
        new = [self.n[a:b] for a, b in ns]
        if len(old) == len(new):
            for span, before, after in zip(ts, old, new, strict=True):
                if before != after:
                    self.replace(*span, after)
            return
        matcher = difflib.SequenceMatcher(None, old, new, autojunk=False)
        for op, i1, i2, j1, j2 in matcher.get_opcodes():
            if op == "replace":
                self.replace_elements(ts, range(i1, i2), new[j1:j2])
            elif op == "delete":
                self.delete_elements(ts, i1, i2)
            elif op == "insert":
                self.insert_elements(ts, t_span, i1, ", ".join(new[j1:j2]))

    def replace_elements(self, ts: list[tuple[int, int]], indices: range, after: list[str]) -> None:
        if len(indices) == len(after):
            for i, text in zip(indices, after, strict=True):
                self.replace(*ts[i], text)
        else:
            self.replace(ts[indices[0]][0], ts[indices[-1]][1], ", ".join(after))

    def delete_elements(self, ts: list[tuple[int, int]], i1: int, i2: int) -> None:
        """Remove elements ``i1:i2`` with the separator that joins them to the rest."""
        # The gaps (comma, spaces, comments) that go with them: those after
        # each, or, for the last elements, the one before them.
        first, last = (i1, i2) if i2 < len(ts) else (max(i1 - 1, 0), i2 - 1)
        gaps = {k: element_gap(self.t, ts[k][1], ts[k + 1][0]) for k in range(first, last)}
        if not any(comment for _, comment in gaps.values()):
            if i2 < len(ts):
                self.replace(ts[i1][0], ts[i2][0], "")
            elif i1 > 0:
                self.replace(ts[i1 - 1][1], ts[i2 - 1][1], "")
            else:
                self.replace(ts[0][0], ts[-1][1], "")
            return
        # A comment there (of an element kept, or of one removed) stays where it
        # is: each element goes with its own comma, a comma on another line
        # alone, and a line the element leaves empty with it.
        commas = {comma for comma, _ in gaps.values()}
        for a, b in ts[i1:i2]:
            after = _past_spaces(self.t, b)
            if after in commas:
                commas.discard(after)
                b = _past_spaces(self.t, after + 1)
            else:
                before = len(self.t[:a].rstrip(" \t")) - 1
                if before in commas:
                    commas.discard(before)
                    a = before
                elif self.starts_line(a):
                    b = after  # its comment moves to where the element began
            line_end = self.t.find("\n", b)
            line_end = len(self.t) if line_end < 0 else line_end
            if self.starts_line(a) and self.t[b:line_end].strip() == "":
                a, b = self.line_start(self.t, a), min(line_end + 1, len(self.t))
            self.replace(a, b, "")
        for comma in commas:
            self.replace(comma, comma + 1, "")

    def insert_elements(
        self, ts: list[tuple[int, int]], t_span: tuple[int, int], i1: int, joined: str
    ) -> None:
        if i1 < len(ts):
            self.replace(ts[i1][0], ts[i1][0], joined + ", ")
        elif ts:
            self.replace(ts[-1][1], ts[-1][1], ", " + joined)
        else:
            self.replace(t_span[0] + 1, t_span[1] - 1, joined)

    def meta(self, t: Statement, o: Statement, n: Statement) -> None:
        before = t.value[1] if t.value else t.head_end
        if n.meta is None:
            if t.meta is not None:
                self.replace(before, t.meta[1], "")
        elif t.meta is None:
            text = self.render(*n.meta, self.indent(self.t, t.start))
            self.replace(before, before, " " + text)
        else:
            self.group(META, _inner(t.meta), _inner(o.meta), _inner(n.meta), t.meta[0])

    # -- removing and adding statements ---------------------------------------------

    def delete(self, t: Statement, context: str) -> _Freed | None:
        """Remove statement ``t``; returns the place it leaves on its own line,
        where a new statement of its kind may go."""
        text = self.t
        start = self.line_start(text, t.start)
        after = _past_spaces(text, t.end)
        at_line_end = after >= len(text) or text[after] == "\n"
        alone = self.starts_line(t.start)
        if alone and at_line_end:
            end = min(after + 1, len(text))
            if t.kind == "prim":
                start, end = self._with_blank_line(start, end)
            self.replace(start, end, "")
            return _Freed(t.kind, start, self.edits[-1], inline=False)
        if context in (META, DICT):
            if after < len(text) and text[after] == ";":
                self.replace(t.start, _past_spaces(text, after + 1), "")
                return None
            before = len(text[: t.start].rstrip(" \t"))
            if before > 0 and text[before - 1] == ";":
                self.replace(before - 1, t.end, "")
                return None
        # A comment after the statement stays where the statement was.
        self.replace(t.start, t.end if at_line_end else after, "")
        return _Freed(t.kind, t.start, self.edits[-1], inline=alone and not at_line_end)

    def _with_blank_line(self, start: int, end: int) -> tuple[int, int]:
        """A removed prim takes one of the blank lines around it along."""
        text = self.t
        previous = self.line_start(text, start - 1) if start > 0 else start
        next_line_end = text.find("\n", end)
        following = text[end : len(text) if next_line_end < 0 else next_line_end]
        if (
            start > 0
            and text[previous:start].strip() == ""
            and (end >= len(text) or following.strip() in ("", "}"))
        ):
            return previous, end
        return start, end

    def delete_lines(self, start: int, end: int) -> None:
        line = self.line_start(self.t, start)
        stop = self.t.find("\n", end)
        self.replace(line, len(self.t) if stop < 0 else stop + 1, "")

    # -- added prims, moves ---------------------------------------------------------

    def added_text(self, n: Statement, indent: str) -> str:
        """The text of a prim Sdf added: the file's own text where it moved from
        another place (``ST008``), Sdf's text otherwise."""
        candidates = self.removed.get(n.key[1])
        if n.kind == "prim" and candidates:
            t, o = candidates.pop(0)
            return self.moved_text(t, o, n, indent)
        if n.body is None or not self._holds_moved(n):
            return self.render(n.start, n.end, indent)
        head = self.render(n.start, n.body[0] + 1, indent)
        inner_indent = indent + self.unit
        parts = [head]
        children = statements(self.n, *_inner(n.body), BODY)
        for index, child in enumerate(children):
            if child.kind == "prim" and index > 0:
                parts.append("")
            parts.append(inner_indent + self.added_text(child, inner_indent))
        parts.append(indent + "}")
        return self.newline.join(parts)

    def _holds_moved(self, n: Statement) -> bool:
        chunk = self.n[n.start : n.end]
        return any(f'"{name}"' in chunk for name, found in self.removed.items() if found)

    def moved_text(self, t: Statement, o: Statement, n: Statement, indent: str) -> str:
        editor = _Editor(self.t, self.o, self.n)
        editor.removed = self.removed
        editor.statement(t, o, n, BODY)
        chunk = apply_edits(self.t, editor.edits, t.start, t.end)
        old_indent = self.indent(self.t, t.start)
        return _shift(chunk, old_indent, indent, self.newline)


class _Placer:
    """Puts the statements Sdf added to one block where they belong in the text."""

    def __init__(self, editor, context, ts, kept, by_key, ns, freed, t_span, opener) -> None:
        self.editor = editor
        self.context = context
        self.ts = ts
        self.kept_keys = {s.key for s in kept}
        self.by_key = by_key
        self.ns = ns
        self.freed = freed
        self.t_span = t_span
        self.opener = opener
        self.indent = self.group_indent()
        self.opened: tuple[int, str, str] | None = None

    def place(self, added: list[Statement]) -> None:
        editor = self.editor
        for n in added:
            if n.kind in ("prim", "variant"):
                position, before, after = self.ordered(n) or self.open()
                if n.kind == "prim":
                    insertion = _Insertion(n, position, self.indent, before, after)
                    editor.insertions.append(insertion)
                    continue
            else:
                position, before, after = self.unordered(n)
            indent = self.indent if not (before == after == "") else ""
            body = editor.render_statement(n, self.indent)
            editor.replace(position, position, before + indent + body + after)

    def group_indent(self) -> str:
        editor = self.editor
        for statement in self.ts:
            if editor.starts_line(statement.start):
                return editor.indent(editor.t, statement.start)
        if self.opener is None:
            return ""
        return editor.indent(editor.t, self.opener) + editor.unit

    def after_line(self, statement: Statement) -> tuple[int, str, str]:
        text, newline = self.editor.t, self.editor.newline
        stop = text.find("\n", statement.end)
        rest = text[statement.end : len(text) if stop < 0 else stop].strip()
        if rest and not rest.startswith(_COMMENT_STARTS):
            # The block's bracket or another statement follows on its line
            # (``( defaultPrim = "Render" )``): a line of its own right after it.
            return statement.end, newline, ""
        if stop < 0:
            return len(text), newline, ""
        return stop + 1, "", newline

    def before_line(self, statement: Statement) -> tuple[int, str, str]:
        return self.editor.line_start(self.editor.t, statement.start), "", self.editor.newline

    def ordered(self, n: Statement) -> tuple[int, str, str] | None:
        """After the nearest earlier sibling the text has, else before the nearest later one."""
        newline = self.editor.newline
        index = self.ns.index(n)
        for previous in reversed(self.ns[:index]):
            if previous.key in self.kept_keys:
                anchor = self.by_key[previous.key][-1]
                position, before, after = self.after_line(anchor)
                return position, before + (newline if anchor.kind == "prim" else ""), after
        for following in self.ns[index + 1 :]:
            if following.key in self.kept_keys:
                anchor = self.by_key[following.key][0]
                position, before, after = self.before_line(anchor)
                return position, before, after + (newline if anchor.kind == "prim" else "")
        return None

    def unordered(self, n: Statement) -> tuple[int, str, str]:
        """Where a removed statement of its kind was, else after the last of its
        kind, else (a property) before the first child prim, else into the block."""
        for index, slot in enumerate(self.freed):
            if slot.kind == n.kind:
                del self.freed[index]
                if not slot.inline:
                    return slot.position, "", self.editor.newline
                # Keep the spaces before the comment: the new statement goes before them.
                slot.edit.end = slot.edit.start + len(
                    self.editor.t[slot.edit.start : slot.edit.end].rstrip(" \t")
                )
                return slot.position, "", ""
        same_kind = [s for s in self.ts if s.kind == n.kind]
        if same_kind:
            return self.after_line(same_kind[-1])
        if n.kind in ("property", "reorder"):
            later = [s for s in self.ts if s.kind in ("prim", "variantSet")]
            if later:
                return self.before_line(later[0])
        return self.open()

    def open(self) -> tuple[int, str, str]:
        """Into the block: at the end of the layer, on the line after the block's
        bracket, or into a bracket pair on one line (then opened over lines)."""
        if self.opened is not None:
            return self.opened
        editor = self.editor
        text, newline = editor.t, editor.newline
        start, end = self.t_span
        if self.opener is None:
            lead = "" if text.endswith("\n") or not text else newline
            self.opened = (len(text), lead, newline)
            return self.opened
        inside = text[start:end]
        if "\n" in inside:
            self.opened = (start + inside.index("\n") + 1, "", newline)
            return self.opened
        editor.replace(start, end, "")  # the spaces of "{ }"
        editor.closings.append((end, newline + editor.indent(text, self.opener)))
        self.opened = (end, newline, "")
        return self.opened


# -- helpers ---------------------------------------------------------------------------

#: How a comment begins in a .usda (Sdf's text format: #, // and /* */).
_COMMENT_STARTS = ("#", "//", "/*")


def _past_spaces(text: str, pos: int) -> int:
    """The offset after the spaces (not line ends) at ``pos``."""
    match = _SPACES.match(text, pos)
    return match.end() if match else pos


def _inner(span: tuple[int, int] | None) -> tuple[int, int]:
    """The inside of a bracketed span (empty for None)."""
    return (span[0] + 1, span[1] - 1) if span else (0, 0)


def _describe(key: tuple[str, ...]) -> str:
    kind, *rest = key
    name = ".".join(part for part in rest if part)
    return f"{kind} {name!r}" if name else kind


def apply_edits(text: str, edits: list[_Edit], start: int = 0, end: int | None = None) -> str:
    """``text[start:end]`` with ``edits`` applied (none may overlap another)."""
    end = len(text) if end is None else end
    out = []
    pos = start
    for edit in sorted(edits):
        if edit.start < pos:
            raise CannotEdit("two parts of the change overlap in the text")
        out.append(text[pos : edit.start])
        out.append(edit.text)
        pos = edit.end
    out.append(text[pos:end])
    return "".join(out)


def _protected(text: str) -> list[tuple[int, int]]:
    """Spans of triple-quoted strings, whose lines are never re-indented."""
    return [m.span() for m in _TRIPLE_STRING.finditer(text)]


def _reindent(text: str, base: str, indent: str, unit: str, newline: str) -> str:
    """Sdf's text (four spaces a level, its first line at ``base``) at ``indent``
    in steps of ``unit``; the first line carries no indentation."""
    strings = _protected(text)
    lines = text.split("\n")
    out = [lines[0]]
    offset = len(lines[0]) + 1
    for line in lines[1:]:
        inside = any(a < offset < b for a, b in strings)
        offset += len(line) + 1
        if inside:
            out.append(line)
        elif not line.strip():
            out.append("")
        else:
            rest = line[len(base) :] if line.startswith(base) else line.lstrip(" ")
            stripped = rest.lstrip(" ")
            levels, extra = divmod(len(rest) - len(stripped), len(_SDF_INDENT))
            out.append(indent + unit * levels + " " * extra + stripped)
    return newline.join(out)


def _shift(text: str, old: str, new: str, newline: str) -> str:
    """The file's own text of a statement moved from indentation ``old`` to ``new``."""
    if old == new:
        return text
    strings = _protected(text)
    lines = text.split("\n")
    out = [lines[0]]
    offset = len(lines[0]) + 1
    for line in lines[1:]:
        inside = any(a < offset < b for a, b in strings)
        offset += len(line) + 1
        out.append(new + line[len(old) :] if not inside and line.startswith(old) else line)
    return "\n".join(out)
