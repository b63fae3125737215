"""Line numbers of prim and property specs in a text ``.usda`` layer.

Sdf keeps no source positions, so a small scanner over the layer text maps each
spec path (variant selections included, as ``Sdf.Spec.path`` spells them) to the
line that opens it. It only needs to be right on files Sdf parsed successfully.

The scan is lazy: a lookup reads only the statements of the bodies on the way to
the spec (the root, then each ancestor prim or variant); every other block (sibling
prims, values, metadata, time samples) is skipped by compiled patterns that match a
whole balanced block in one call, so Python runs once per statement read, not per token.
Where laziness stops paying (many lookups deep in large blocks, or long lines of large
arrays that cost as much to skip as to read) the layer is read whole, once.

Tokens follow one fixed tokenization: comments, strings, asset paths, ``<paths>`` and
words (``float3[]``, ``xformOp:translate.timeSamples``: brackets inside a word belong
to it) are atoms; ``( [ ) ]`` outside atoms nest interchangeably and hide braces and
line ends; ``{ }`` open and close blocks; a statement ends at a line end or a brace.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Callable
from dataclasses import field
from typing import TypeVar, cast

from ..api.cache import active_cache
from ..records import record

#: Characters that never start an atom, a block or a word (numbers, "=", spaces...).
_INERT = r"""[^\n"'@<#/{}()\[\]A-Za-z_]"""
_COMMENT = r"\#[^\n]*|//[^\n]*|/\*.*?\*/"
_STRING = r'""".*?"""|' r"'''.*?'''|" r'"(?:[^"\\\n]++|\\.)*+"|' r"'(?:[^'\\\n]++|\\.)*+'"
_ASSET = r"@@@.*?@@@|@[^@\n]*@"
_PATH = r"<[^>\n]*>"
#: A word may end in "[]" (``float3[]``), never hold another bracket: in ``1e-05]`` the
#: word is ``e-05`` and the bracket closes the array.
_WORD = r"[A-Za-z_][\w:.-]*+(?:\[\])?+"
#: A quote, "@", "<" or "/" that opens no atom stands alone.
_LONE = r"""["'@</]"""
#: Atoms other than words; where two start alike the first that matches wins, as in
#: a left-to-right tokenizer ('"""' before '"', '//' before a lone '/').
_ATOMS = f"{_COMMENT}|{_STRING}|{_ASSET}|{_PATH}|{_LONE}"
#: Nesting the patterns below match in one call; deeper blocks are walked in Python.
#: Compile time grows fast with it (2: ~8 ms, 8: ~55 ms) while lookups on the corpus
#: and the benchmark shots run as fast at 2 as at 8.
_DEPTH = 2
#: What ends a run: a bracket, an atom, and outside brackets a brace (and for a
#: statement a line end or ";", which separates statements on one line as a line end
#: does). Only atoms and brackets matter inside brackets.
_IN_BRACKETS_STOP = r"""()\[\]"'@<#/"""
_OUTSIDE_STOP = "{}" + _IN_BRACKETS_STOP
_STATEMENT_STOP = "\\n;" + _OUTSIDE_STOP
#: The characters that end a statement: a line end, ";" or a brace.
_STATEMENT_ENDS = "\n;{}"


def _runs(stop: str, items: str) -> str:
    """Text up to an unmatched ``stop`` character: inert runs, words and ``items``.

    Unrolled as run (item run)*, one loop turn per item; possessive, so that what
    an alternative matched is final, as for a tokenizer.
    """
    run = f"[^{stop}A-Za-z_]*+"
    return f"(?>{run}(?:(?:{_WORD}|{items}){run})*+)"


def _bracket_group(depth: int) -> str:
    # "(0, 1e-05, 0)" first: the commonest group, matched without recursing (a word
    # in it holds no bracket: there is none)
    simple = f"\\([^{_IN_BRACKETS_STOP}]*+\\)"
    inner = "" if depth == 1 else "|" + _bracket_group(depth - 1)
    return rf"[(\[]{_runs(_IN_BRACKETS_STOP, f'{simple}{inner}|{_ATOMS}')}[)\]]"


def _flat(group: str, depth: int) -> str:
    """Text that leaves brace depth unchanged: atoms, bracket groups, whole blocks."""
    block = "" if depth == 0 else rf"|\{{{_flat(group, depth - 1)}\}}"
    return _runs(_OUTSIDE_STOP, f"{group}{block}|{_ATOMS}")


def _compile(pattern: str) -> re.Pattern[str]:
    return re.compile(pattern, re.DOTALL)


#: ``Pattern.match`` of a pattern that matches at every offset (possibly nothing).
_MatchAt = Callable[[str, int], re.Match[str]]
#: The text, or a layer's skeleton (its bytes).
_Subject = TypeVar("_Subject", str, bytes)


def _match_at(pattern: str) -> _MatchAt:
    # cast: every such pattern is a possessive repetition (``(...)*+``), which
    # matches the empty string, so match() never returns None
    return cast(_MatchAt, _compile(pattern).match)


#: A bracket group nested up to _DEPTH deep (text of a pattern, not compiled).
_GROUP = _bracket_group(_DEPTH)


class _Skippers:
    """The patterns that match nested groups and blocks whole. Each is compiled on
    its first use, not at import: each takes a few ms to compile, and most files
    have no finding to place. Placing one in an ASCII layer Sdf read skips blocks
    over its skeleton and never needs ``flat`` (8 ms of the 17)."""

    @functools.cached_property
    def skeleton_flat(self) -> Callable[[bytes, int], re.Match[bytes]]:
        """In a skeleton, up to an unmatched brace."""
        match = re.compile(_skeleton_flat(_DEPTH), re.DOTALL).match
        return cast(Callable[[bytes, int], re.Match[bytes]], match)

    @functools.cached_property
    def flat(self) -> _MatchAt:
        """Up to an unmatched brace or bracket."""
        return _match_at(_flat(_GROUP, _DEPTH))

    @functools.cached_property
    def in_brackets(self) -> _MatchAt:
        """Up to an unmatched bracket."""
        return _match_at(_runs(_IN_BRACKETS_STOP, f"{_GROUP}|{_ATOMS}"))

    @functools.cached_property
    def statement_rest(self) -> _MatchAt:
        """Up to the end of a statement (a line end or brace) or a bracket too deep to match."""
        return _match_at(_runs(_STATEMENT_STOP, f"{_GROUP}|{_ATOMS}"))

    @functools.cached_property
    def to_word(self) -> _MatchAt:
        """Up to the next word of a statement (words inside brackets do not count)."""
        run = f"[^{_STATEMENT_STOP}A-Za-z_]*+"
        return _match_at(f"{run}(?:(?:{_GROUP}|{_ATOMS}){run})*+")


_SKIPPERS = _Skippers()


#: What a block of a layer Sdf has read is skipped by: its braces balance outside
#: atoms everywhere (inside brackets too: a dictionary in metadata), so brackets
#: and words need no reading. The skip runs over the layer's *skeleton*, its bytes
#: with every byte that no atom or brace pattern reads by name made "x": sre
#: matches a run of one literal some ten times faster than a run of a class.
_SKELETON_KEPT = b"{}\"'@<>#/*\\\n"
_SKELETON = bytes(byte if byte in _SKELETON_KEPT else ord("x") for byte in range(256))


def _skeleton_flat(depth: int) -> bytes:
    """Skeleton bytes that leave brace depth unchanged: runs, atoms, whole blocks."""
    run = rb"x*+(?:[\n>*\\]x*+)*+"
    block = b"" if depth == 0 else rb"|\{" + _skeleton_flat(depth - 1) + rb"\}"
    return rb"(?>" + run + rb"(?:(?:" + _ATOMS.encode() + block + rb")" + run + rb")*+)"


_INERT_GROUP = rf"\({_INERT}*\)"
#: What a tokenizer drops between tokens: spaces, numbers, comments, (0, 1) runs.
_gap_at = _match_at(rf"(?:{_INERT}++|{_COMMENT}|{_INERT_GROUP})*+")
#: The same, line ends included: what precedes the first token of a statement.
_blank_at = _match_at(rf"(?:{_INERT}++|\n|{_COMMENT}|{_INERT_GROUP})*+")
_WORD_AT = _compile(_WORD)
_ATOM_AT = _compile(_ATOMS)
_STRING_AT = _compile(_STRING)

_PROPERTY_QUALIFIERS = {
    "custom",
    "uniform",
    "varying",
    "config",
    "prepend",
    "append",
    "add",
    "delete",
    "reorder",
}
_PRIM_SPECIFIERS = {"def", "over", "class"}
_SPEC_FRAMES = ("prim", "variant")
#: Where a frame's path can end inside a spec path: before "/", "." or "{" (a prim),
#: or after "=" (a variant set) or "}" (a variant).
_FRAME_END_BEFORE = frozenset("/.{")
_FRAME_END_AFTER = frozenset("=}")
#: Skipping this many characters takes about as long as reading one line's statement
#: (measured on statement-dense and on array-dense layers).
_LINE_COST = 200


def _unquote(token: str) -> str:
    for quote in ('"""', "'''", '"', "'"):
        if token.startswith(quote) and token.endswith(quote) and len(token) >= 2 * len(quote):
            return token[len(quote) : -len(quote)]
    return token


def _prim_path(parent: str, name: str) -> str:
    # Inside a variant Sdf spells the child right after the selection: /A{v=x}B
    return parent + name if parent.endswith("}") else parent + "/" + name


@record
class _Layer:
    """The lines found so far in one layer's text and the blocks not read yet."""

    text: str
    #: True for the text of a layer Sdf has read (a stage's): its blocks are skipped
    #: over its skeleton. Other text (any the tests make) is tokenized throughout.
    read_by_sdf: bool = False
    lines: dict[str, int] = field(default_factory=dict)
    #: Frame path -> (kind, offsets after its "{" and "}") of each block that opens it.
    bodies: dict[str, list[tuple[str, int, int]]] = field(default_factory=dict)
    read: set[str] = field(default_factory=set)
    #: Characters read so far (a block's text is read again for each frame read in it).
    spent: int = 0
    complete: bool = False
    _line_at: tuple[int, int] = (0, 1)
    _newlines: int = -1
    #: The skeleton of an ASCII text Sdf has read (b"" for others), made on the first skip.
    _skeleton: bytes | None = None

    def line(self, offset: int) -> int:
        # Counted from the last line asked for: lookups ask for nearby offsets.
        base, line = self._line_at
        if offset < base:
            line -= self.text.count("\n", offset, base)
        else:
            line += self.text.count("\n", base, offset)
        self._line_at = (offset, line)
        return line

    def lookup(self, spec_path: str) -> int | None:
        if spec_path not in self.lines and not self.complete:
            # Read the frames along the path, outermost first (each read finds the next).
            self._read_frame("")
            for i, char in enumerate(spec_path):
                if char in _FRAME_END_BEFORE:
                    self._read_frame(spec_path[:i])
                elif char in _FRAME_END_AFTER:
                    self._read_frame(spec_path[: i + 1])
        return self.lines.get(spec_path)

    def read_all(self) -> dict[str, int]:
        self._scan("prim", "", 0, root=True, eager=True)
        self.complete = True
        return self.lines

    def _full_read_cost(self) -> int:
        """A full read's cost, in characters skipped in the same time."""
        if self._newlines < 0:
            self._newlines = self.text.count("\n")
        return len(self.text) + _LINE_COST * self._newlines

    def _read_frame(self, path: str) -> None:
        if path in self.read or self.complete:
            return
        if path == "":
            if self._full_read_cost() < 2 * len(self.text):
                # Long lines (large arrays): skipping costs about what reading does,
                # so laziness saves little and a full read is never paid twice.
                self.read_all()
                return
            self.read.add(path)
            self.spent += len(self.text)
            self._scan("prim", "", 0, root=True, eager=False)
        elif path in self.bodies:
            blocks = self.bodies[path]
            size = sum(end - start for _, start, end in blocks)
            if self.spent + size > self._full_read_cost():
                # Once lazy reads would have cost what one full read does, read it all
                # (at most about twice the cost of the better choice in hindsight).
                self.read_all()
                return
            self.read.add(path)
            self.spent += size
            for kind, start, _ in blocks:
                self._scan(kind, path, start, root=False, eager=False)

    def _scan(self, kind: str, path: str, pos: int, *, root: bool, eager: bool) -> None:
        """Read the statements of one block from ``pos`` to its closing brace.

        Child blocks are remembered and skipped, or read in place when ``eager``.
        """
        text = self.text
        end = len(text)
        stack = [(kind, path)]
        pending: tuple[str, str] | None = None  # the frame the next "{" opens
        while True:
            pos = _blank_at(text, pos).end()
            if pos >= end:
                return
            top_kind, top_path = stack[-1]
            char = text[pos]
            if char == "{" or char == "}":
                pos, pending = self._brace(stack, pending, pos, root=root, eager=eager)
                if not stack:
                    return
                continue
            start = pos
            name: str | None = None
            if char.isascii() and (char.isalpha() or char == "_"):
                pos, name, opened = self._word_statement(start, top_kind, top_path)
            else:
                pos, opened = _skip_token(text, pos, top_kind, top_path)
            if opened is not None:
                pending = opened
            pos = _statement_end(text, pos)
            if name is not None and (pos >= end or text[pos] != "}"):
                self.lines.setdefault(top_path + "." + name, self.line(start))

    def _word_statement(
        self, start: int, top_kind: str, top_path: str
    ) -> tuple[int, str | None, tuple[str, str] | None]:
        """Read the head of a statement that starts with a word: a prim (its line is
        recorded), a variant set, or a property. Returns where the head ends, the
        property's name, and the frame the next "{" opens."""
        text = self.text
        word_at = _WORD_AT.match(text, start)
        assert word_at is not None  # the statement starts with a word
        word = word_at.group()
        pos = start + len(word)
        in_spec = top_kind in _SPEC_FRAMES
        if in_spec and word in _PRIM_SPECIFIERS:
            quoted = _prim_name(text, pos)
            if quoted is None:
                return pos, None, None
            prim = _prim_path(top_path, _unquote(quoted.group()))
            self.lines.setdefault(prim, self.line(start))
            return quoted.end(), None, ("prim", prim)
        if in_spec and word == "variantSet":
            string = _STRING_AT.match(text, _gap_at(text, pos).end())
            if string is None:
                return pos, None, None
            return pos, None, ("variantset", top_path + "{" + _unquote(string.group()) + "=")
        if not (in_spec and top_path):
            return pos, None, None
        pos, name = _property_name(text, pos, [] if word in _PROPERTY_QUALIFIERS else [word])
        return pos, name, None

    def _brace(
        self,
        stack: list[tuple[str, str]],
        pending: tuple[str, str] | None,
        pos: int,
        *,
        root: bool,
        eager: bool,
    ) -> tuple[int, tuple[str, str] | None]:
        text = self.text
        if text[pos] == "}":
            if len(stack) > 1 or not root:
                stack.pop()
            return pos + 1, pending
        pos += 1
        if eager and pending is not None:
            stack.append(pending)
            return pos, None
        end = self._skip_block(pos)
        if pending is not None:
            self.bodies.setdefault(pending[1], []).append((pending[0], pos, end))
        # else a value or dictionary block: nothing to find inside
        return end, None

    def _skip_block(self, pos: int) -> int:
        """The offset after the brace that closes the one just before ``pos``."""
        skeleton = self._skeleton
        if skeleton is None:
            text = self.text
            # A skeleton's offsets are the text's only where each character is one byte.
            usable = self.read_by_sdf and text.isascii()
            skeleton = self._skeleton = text.encode("ascii").translate(_SKELETON) if usable else b""
        if not skeleton:
            return _skip_block(self.text, pos)
        return _after_closing(skeleton, pos, _SKIPPERS.skeleton_flat, b"{")


def _skip_token(
    text: str, pos: int, top_kind: str, top_path: str
) -> tuple[int, tuple[str, str] | None]:
    """Skip the first token of a statement that does not start with a word (a bracket
    group, a string, an asset path, a <path>, a lone "@", "<" or "/", or a stray ")"
    or "]"). Returns the offset after it and, for a variant's name in a variant set,
    the frame the next "{" opens."""
    char = text[pos]
    if char in "([":
        return _skip_brackets(text, pos + 1), None
    if char == '"' or char == "'":
        string = _STRING_AT.match(text, pos)
        if string is None:
            return pos + 1, None
        if top_kind == "variantset":
            return string.end(), ("variant", top_path + _unquote(string.group()) + "}")
        return string.end(), None
    atom = _ATOM_AT.match(text, pos)
    return (atom.end() if atom else pos + 1), None


def _skip_brackets(text: str, pos: int) -> int:
    """The offset after the bracket that closes the one just before ``pos``."""
    return _after_closing(text, pos, _SKIPPERS.in_brackets, "([")


def _after_closing(
    subject: _Subject,
    pos: int,
    run: Callable[[_Subject, int], re.Match[_Subject]],
    openers: _Subject,
) -> int:
    """The offset after the closer of the opener just before ``pos`` (or the end).
    ``run`` matches the runs and atoms up to the next opener or closer; a character
    in ``openers`` (a byte of a skeleton: ``in`` bytes tests its number) opens a
    level, any other it stops at closes one."""
    depth = 1
    end = len(subject)
    while True:
        pos = run(subject, pos).end()
        if pos >= end:
            return end
        depth += 1 if subject[pos] in openers else -1
        pos += 1
        if depth == 0:
            return pos


def _skip_block(text: str, pos: int) -> int:
    """The offset after the brace that closes the one just before ``pos``."""
    depth = 1
    end = len(text)
    flat = _SKIPPERS.flat
    while True:
        pos = flat(text, pos).end()
        if pos >= end:
            return end
        char = text[pos]
        pos += 1
        if char == "{":
            depth += 1
        elif char == "}":
            depth -= 1
            if depth == 0:
                return pos
        elif char in "([":
            pos = _skip_brackets(text, pos)
        # else a stray closing bracket: changes nothing


def _statement_end(text: str, pos: int) -> int:
    """The offset of the line end or brace that ends the statement (or the text's end)."""
    end = len(text)
    statement_rest = _SKIPPERS.statement_rest
    while True:
        pos = statement_rest(text, pos).end()
        if pos >= end or text[pos] in _STATEMENT_ENDS:
            return pos
        # an opening bracket nested too deep to match at once, or a stray closing one
        pos = _skip_brackets(text, pos + 1) if text[pos] in "([" else pos + 1


def _prim_name(text: str, pos: int) -> re.Match[str] | None:
    """After ``def``/``over``/``class``: the name string past the type's words, if any."""
    while True:
        pos = _gap_at(text, pos).end()
        word = _WORD_AT.match(text, pos)
        if word is None:
            return _STRING_AT.match(text, pos)
        pos = word.end()


def _property_name(text: str, pos: int, rest: list[str]) -> tuple[int, str | None]:
    """Read a statement's words up to its second unqualified one (``float3[] extent``):
    the property it declares, without a ``.timeSamples``/``.connect`` suffix."""
    end = len(text)
    to_word = _SKIPPERS.to_word
    while len(rest) < 2:
        pos = to_word(text, pos).end()
        if pos >= end or text[pos] in _STATEMENT_ENDS:
            break
        if text[pos] in "([":
            pos = _skip_brackets(text, pos + 1)
            continue
        if text[pos] in ")]":  # a stray closing bracket changes nothing
            pos += 1
            continue
        word_at = _WORD_AT.match(text, pos)
        assert word_at is not None  # past the checks above, to_word stopped at a word
        word = word_at.group()
        pos += len(word)
        if word not in _PROPERTY_QUALIFIERS:
            rest.append(word)
    return pos, rest[1].split(".")[0] if len(rest) >= 2 else None


def index_usda(text: str) -> dict[str, int]:
    """Map spec paths (``/A/B``, ``/A{v=x}B.attr``) to 1-based line numbers."""
    return _Layer(text).read_all()


def _read_layer(layer_path: str) -> _Layer:
    try:
        with open(layer_path, encoding="utf-8", errors="replace") as handle:
            text = handle.read()
    except OSError:
        text = ""
    return _Layer(text, read_by_sdf=True)


def line_of(layer_path: str, spec_path: str) -> int | None:
    """The line of ``spec_path`` in the text layer at ``layer_path``, if found.
    Inside a lint the layer's index lives in the lint's cache (read once per
    lint, dropped with it); outside one the layer is read for this lookup."""
    cache = active_cache()
    layer = _read_layer(layer_path) if cache is None else cache.call(_read_layer, layer_path)
    return layer.lookup(spec_path)


def hold_text(layer_path: str, text: str) -> None:
    """Inside a lint, find the specs of the layer at ``layer_path`` in ``text``
    (an editor's unsaved text of it) instead of in its file."""
    cache = active_cache()
    if cache is not None:
        cache.put(_read_layer, (layer_path,), _Layer(text, read_by_sdf=True))


def comment_lines(text: str) -> list[int]:
    """The lines where a ``#``, ``//`` or ``/* */`` comment starts, the ``#usda``
    header excepted: what Sdf drops when it saves the layer again."""
    found = []
    line, counted = 1, 0
    for match in _SPANS.comment_or_atom.finditer(text):
        if match.group(1) is not None and match.start() != 0:
            line += text.count("\n", counted, match.start())
            counted = match.start()
            found.append(line)
    return found


# -- statement spans, for text edits ---------------------------------------------------
#
# A fix edits a layer through Sdf; the fixing package then writes that change
# into the file's own text (usdrender_lint.fixing.text_edits). For that it needs
# the statements of one block at a time, each with the spans of its parts: the
# words of its head (``uniform token[] purposes``, ``def Scope "Render"``), the
# value after ``=``, the ``( ... )`` metadata and the ``{ ... }`` body. The same
# parser reads the file and Sdf's export of it, so statements pair up by key.

#: The contexts a block's statements are read in: a prim's (or variant's, or the
#: layer's top-level) body, a ``( ... )`` metadata list, a dictionary value, the
#: variants of a variantSet.
BODY, META, DICT, VARIANTS = "body", "meta", "dict", "variants"
_LIST_OPS = frozenset({"prepend", "append", "add", "delete", "reorder"})


class _Spans:
    """The patterns only the statement spans and :func:`comment_lines` use (the
    fixes), compiled on first use: locating a finding, the one use of this module
    in most runs, needs none of them (about 0.5 ms of a check's start-up)."""

    @functools.cached_property
    def inline_gap(self) -> re.Pattern[str]:
        """Spaces, and /* */ comments, which never end a statement."""
        return _compile(r"(?:[ \t\r\f\v]++|/\*.*?\*/)*+")

    @functools.cached_property
    def gap_lines(self) -> re.Pattern[str]:
        return _compile(r"(?:[ \t\r\f\v\n]++|\#[^\n]*+|//[^\n]*+|/\*.*?\*/)*+")

    @functools.cached_property
    def gap_entries(self) -> re.Pattern[str]:
        return _compile(r"(?:[ \t\r\f\v\n;]++|\#[^\n]*+|//[^\n]*+|/\*.*?\*/)*+")

    @functools.cached_property
    def bare_at(self) -> re.Pattern[str]:
        """A number, ``None``, ``true``, ``-inf``: what is left of a value once atoms are out."""
        return _compile(r"""[^\s"'@<#/{}()\[\]=,;]++""")

    @functools.cached_property
    def asset_at(self) -> re.Pattern[str]:
        return _compile(_ASSET)

    @functools.cached_property
    def path_at(self) -> re.Pattern[str]:
        return _compile(_PATH)

    @functools.cached_property
    def comment_or_atom(self) -> re.Pattern[str]:
        """A comment (group 1), or an atom that may hold comment characters."""
        return _compile(f"({_COMMENT})|{_STRING}|{_ASSET}|{_PATH}")


_SPANS = _Spans()


@record(frozen=True)
class Statement:
    """One statement of a layer's text: offsets of the whole and of its parts.

    ``key`` pairs it with the same statement in another text of the same layer
    (a prim or variant by name, a property by name, list operation and suffix
    such as ``timeSamples``, an entry by list operation and name). ``value``,
    ``meta`` and ``body`` include their brackets.
    """

    kind: str  # "prim", "property", "variantSet", "variant", "reorder", "entry", "other"
    key: tuple[str, ...]
    start: int
    end: int
    words: tuple[tuple[int, int], ...] = ()
    value: tuple[int, int] | None = None
    meta: tuple[int, int] | None = None
    body: tuple[int, int] | None = None

    @property
    def head_end(self) -> int:
        return self.words[-1][1] if self.words else self.start


@record(frozen=True)
class LayerText:
    """The top of a text layer: the header line, the layer metadata, the body."""

    header_end: int  # after the header line's line end
    meta: tuple[int, int] | None
    body: tuple[int, int]


def _past(pattern: re.Pattern[str], text: str, pos: int, end: int | None = None) -> int:
    """Where ``pattern`` (which matches the empty string too) stops matching."""
    match = pattern.match(text, pos, len(text) if end is None else end)
    return match.end() if match else pos


def _token_end(text: str, pos: int) -> int:
    """The end of the token at ``pos`` (not a gap): an atom, a bracket group or
    block as a whole, a word or a bare run, else one character."""
    char = text[pos]
    if char in "([":
        return _skip_brackets(text, pos + 1)
    if char == "{":
        return _skip_block(text, pos + 1)
    spans = _SPANS
    pattern = {'"': _STRING_AT, "'": _STRING_AT, "@": spans.asset_at, "<": spans.path_at}.get(char)
    if pattern is None:
        pattern = _WORD_AT if char.isalpha() or char == "_" else spans.bare_at
    match = pattern.match(text, pos)
    return match.end() if match and match.end() > pos else pos + 1


def _ends_statement(text: str, pos: int, closers: str) -> bool:
    char = text[pos]
    return char == "\n" or char == "#" or char in closers or text.startswith("//", pos)


def _head(text: str, pos: int, end: int, stop: str) -> tuple[list[tuple[int, int]], int]:
    """The words of a statement's head, up to ``=``, a line end, or a ``stop`` character."""
    words: list[tuple[int, int]] = []
    while True:
        pos = _past(_SPANS.inline_gap, text, pos)
        if pos >= end or _ends_statement(text, pos, stop):
            return words, pos
        after = _token_end(text, pos)
        words.append((pos, after))
        pos = after


def _word(text: str, span: tuple[int, int]) -> str:
    return _unquote(text[span[0] : span[1]])


def _group_after(text: str, pos: int, end: int, opener: str) -> tuple[int, int] | None:
    """The ``opener`` group starting after a gap (line ends and comments allowed)."""
    pos = _past(_SPANS.gap_lines, text, pos)
    if pos < end and text[pos] == opener:
        return pos, _token_end(text, pos)
    return None


def _body_statement(text: str, pos: int, end: int) -> Statement:
    start = pos
    words, pos = _head(text, pos, end, "=({}")
    names = [_word(text, w) for w in words]
    first = names[0] if names else ""
    if first in _PRIM_SPECIFIERS and len(words) >= 2:
        meta, body, stop = _meta_and_body(text, pos, end)
        return Statement("prim", ("prim", names[-1]), start, stop, tuple(words), None, meta, body)
    if first == "variantSet" and len(words) == 2 and pos < end and text[pos] == "=":
        block = _group_after(text, pos + 1, end, "{")
        return _variant_set(start, pos, tuple(words), names[1], block)
    value, meta, pos = _value_and_meta(text, pos, end)
    stop = meta[1] if meta else value[1] if value else words[-1][1] if words else pos
    key = _property_key(names)
    if key is None:
        if stop <= start:
            stop = _token_end(text, start)
        key = ("other", text[start:stop])
    return Statement(key[0], key, start, stop, tuple(words), value, meta)


def _variant_set(
    start: int,
    equals: int,
    words: tuple[tuple[int, int], ...],
    name: str,
    block: tuple[int, int] | None,
) -> Statement:
    """``variantSet "name" = { ... }``; without its block it ends after the ``=``."""
    stop = block[1] if block else equals + 1
    return Statement("variantSet", ("variantSet", name), start, stop, words, block)


def _meta_and_body(
    text: str, pos: int, end: int
) -> tuple[tuple[int, int] | None, tuple[int, int] | None, int]:
    """The ``( )`` metadata and ``{ }`` body after a prim's or variant's name, and
    where the statement ends."""
    meta = _group_after(text, pos, end, "(")
    body = _group_after(text, meta[1] if meta else pos, end, "{")
    return meta, body, body[1] if body else meta[1] if meta else pos


def _value_and_meta(
    text: str, pos: int, end: int
) -> tuple[tuple[int, int] | None, tuple[int, int] | None, int]:
    """The ``= value`` and ``( )`` metadata after a statement's head, and where
    the head or the value ends."""
    value = None
    if pos < end and text[pos] == "=":
        pos = _past(_SPANS.inline_gap, text, pos + 1)
        if pos < end and not _ends_statement(text, pos, "}"):
            value = (pos, _token_end(text, pos))
            pos = value[1]
    meta = None
    after = _past(_SPANS.inline_gap, text, pos)
    if after < end and text[after] == "(":
        meta = (after, _token_end(text, after))
    return value, meta, pos


def _property_key(names: list[str]) -> tuple[str, ...] | None:
    """The key of a statement that is not a prim or variant set: a reorder, a
    property (by name, list operation and suffix), or None (something else)."""
    first = names[0] if names else ""
    if first == "reorder" and len(names) == 2 and names[1] in ("nameChildren", "properties"):
        return ("reorder", names[1])
    qualifiers = [n for n in names if n in _PROPERTY_QUALIFIERS]
    if len(names) >= 2 and len(qualifiers) < len(names):
        name, _, suffix = names[-1].partition(".")
        return ("property", name, first if first in _LIST_OPS else "", suffix)
    return None


def _entry_statement(text: str, pos: int, end: int, closer: str) -> Statement:
    """A metadata or dictionary entry: ``[op] [type] name = value``, or a bare doc string."""
    start = pos
    words, pos = _head(text, pos, end, "=;" + closer)
    names = [_word(text, w) for w in words]
    if pos >= end or text[pos] != "=":
        if len(words) == 1 and text[words[0][0]] in "\"'":
            return Statement("entry", ("entry", "", "doc"), start, words[0][1], (), words[0])
        stop = words[-1][1] if words else _token_end(text, start)
        return Statement("other", ("other", text[start:stop]), start, stop, tuple(words))
    pos = _past(_SPANS.inline_gap, text, pos + 1)
    value_start, value_end = pos, pos
    while pos < end and not _ends_statement(text, pos, ";" + closer):
        value_end = _token_end(text, pos)
        pos = _past(_SPANS.inline_gap, text, value_end)
    op = names[0] if len(names) > 1 and names[0] in _LIST_OPS else ""
    value = (value_start, value_end) if value_end > value_start else None
    stop = value_end if value else pos
    name = names[-1] if names else ""
    return Statement("entry", ("entry", op, name), start, stop, tuple(words), value)


def _variant_statement(text: str, pos: int, end: int) -> Statement:
    start = pos
    name_end = _token_end(text, pos)
    meta, body, stop = _meta_and_body(text, name_end, end)
    name = _unquote(text[start:name_end])
    return Statement(
        "variant", ("variant", name), start, stop, ((start, name_end),), None, meta, body
    )


def statements(text: str, start: int, end: int, context: str) -> list[Statement]:
    """The statements between ``start`` and ``end`` (the inside of a block)."""
    entries = context in (META, DICT)
    gap = _SPANS.gap_entries if entries else _SPANS.gap_lines
    closer = ")" if context == META else "}"
    found: list[Statement] = []
    pos = start
    while True:
        pos = _past(gap, text, pos, end)
        if pos >= end:
            return found
        if entries:
            statement = _entry_statement(text, pos, end, closer)
        elif context == VARIANTS:
            statement = _variant_statement(text, pos, end)
        else:
            statement = _body_statement(text, pos, end)
        found.append(statement)
        pos = max(statement.end, pos + 1)


def layer_text(text: str) -> LayerText:
    """Where the header line, the layer metadata and the body of a text layer are."""
    newline = text.find("\n")
    header_end = len(text) if newline < 0 else newline + 1
    meta = _group_after(text, header_end, len(text), "(")
    return LayerText(header_end, meta, (meta[1] if meta else header_end, len(text)))


def element_gap(text: str, start: int, end: int) -> tuple[int, bool]:
    """Between two elements of ``element_spans`` (``text[start:end]``): the
    offset of the comma that separates them, and whether a comment is there."""
    comma = _past(_SPANS.gap_lines, text, start, end)
    gap = text[start:end]
    return comma, "#" in gap or "//" in gap or "/*" in gap


def element_spans(text: str, span: tuple[int, int]) -> list[tuple[int, int]]:
    """The elements of the ``[ ... ]`` or ``( ... )`` at ``span``, without the
    commas, spaces and comments between them."""
    end = span[1] - 1
    found: list[tuple[int, int]] = []
    pos = span[0] + 1
    while True:
        pos = _past(_SPANS.gap_lines, text, pos, end)
        if pos >= end:
            return found
        if text[pos] == ",":
            pos += 1
            continue
        first = last = pos
        while pos < end and text[pos] != ",":
            last = _token_end(text, pos)
            pos = _past(_SPANS.gap_lines, text, last, end)
        found.append((first, last))
