"""A validating parser for light path expressions (LPEs), shared by the VA rules.

The grammar is OSL's (``src/liboslexec/lpeparse.cpp``), restated here:

* an expression is a sequence of elements; ``|`` alternates the element before
  it with the element after it;
* an element is a label, a quoted custom label ``'name'``, a group
  ``( ... )``, a set ``[ ... ]`` (any of its elements), a negated set
  ``[^ ... ]`` (any label but the listed ones; labels only, never empty) or an
  event ``< ... >`` whose first position is the event type, second the
  scattering type and the rest custom labels (no ``<`` and no repetition inside);
* an element may carry one modifier: ``*``, ``+``, ``{n}``, ``{n,}`` or
  ``{n,m}``;
* labels: event types ``C L B V T R O``, scattering types ``D G S s``, ``.``
  (any) and ``x`` (none).

Beyond what OSL rejects, the catalog (VA003) also rejects a label in the wrong
position of ``<...>`` (OSL accepts ``<DR>``, which can never match) and an
expression that cannot begin with the camera event ``C``. The ``extended``
dialect admits renderer extensions: the ``?`` modifier and any other label.
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import lru_cache
from typing import Literal

from usdrender_lint.api import record

Dialect = Literal["osl", "extended"]

EVENT_TYPES = frozenset("CLBVTRO")
SCATTERING_TYPES = frozenset("DGSs")
WILDCARD = "."
NONE_LABEL = "x"
KNOWN_LABELS = EVENT_TYPES | SCATTERING_TYPES | {WILDCARD, NONE_LABEL}
#: The prefix some renderers want on LPE sources; hdPrman adds it itself.
RENDERER_PREFIX = "lpe:"
_POSITION_LABELS = (
    (EVENT_TYPES, "an event type (C L B V T R O)"),
    (SCATTERING_TYPES, "a scattering type (D G S s)"),
)
_UNBOUNDED = -1
#: Deeper nesting is reported instead of parsed (the parser recurses per level).
MAX_NESTING = 100


@record(frozen=True)
class LpeProblem:
    """Why an expression is malformed; ``position`` is a 0-based character index."""

    message: str
    position: int

    def __str__(self) -> str:
        return f"{self.message} (at character {self.position + 1})"


@record(frozen=True)
class Node:
    """One parsed element: ``kind`` is label, custom, event, set, negset, cat or alt."""

    kind: str
    text: str = ""
    children: tuple[Node, ...] = ()
    min_repeat: int = 1
    max_repeat: int = 1


class _Malformed(Exception):
    def __init__(self, message: str, position: int) -> None:
        super().__init__(message)
        self.problem = LpeProblem(message, position)


def strip_renderer_prefix(text: str) -> tuple[str, bool]:
    """The expression without one leading ``lpe:``, and whether it had one."""
    if text.startswith(RENDERER_PREFIX):
        return text[len(RENDERER_PREFIX) :], True
    return text, False


def parse_lpe(text: str, dialect: Dialect = "osl", extra_labels: tuple[str, ...] = ()) -> Node:
    """Parse an expression; raise ``ValueError`` carrying an :class:`LpeProblem`."""
    try:
        return _Parser(text, dialect, frozenset(extra_labels)).parse()
    except _Malformed as exc:
        raise ValueError(exc.problem) from None


def lpe_problem(
    text: str, dialect: Dialect = "osl", extra_labels: Iterable[str] = ()
) -> LpeProblem | None:
    """Why ``text`` is not a valid LPE of ``dialect``, or None when it is."""
    return _lpe_problem(text, dialect, tuple(extra_labels))


# A pure function of its strings: shots repeat the same few expressions, and a
# parse costs ~10-20 us. Bounded, so hostile input cannot grow it without limit.
@lru_cache(maxsize=1024)
def _lpe_problem(text: str, dialect: Dialect, extra_labels: tuple[str, ...]) -> LpeProblem | None:
    try:
        parse_lpe(text, dialect, extra_labels)
    except ValueError as exc:
        return exc.args[0]
    return None


class _Parser:
    def __init__(self, text: str, dialect: Dialect, extra_labels: frozenset[str]) -> None:
        self.text = text
        self.pos = 0
        self.extended = dialect == "extended"
        self.extra_labels = extra_labels
        self.in_event = False
        self.depth = 0

    def parse(self) -> Node:
        if not self.text:
            raise _Malformed("the expression is empty", 0)
        tree = self.sequence(None)
        if not _can_start_with_camera(tree):
            raise _Malformed("the expression must begin with the camera event C", 0)
        return tree

    def peek(self) -> str | None:
        return self.text[self.pos] if self.pos < len(self.text) else None

    # -- elements ----------------------------------------------------------------

    def sequence(self, closer: str | None, position: int | None = None) -> Node:
        items: list[Node] = []
        while (char := self.peek()) is not None and char != closer:
            if char == "|":
                if not items:
                    raise _Malformed("'|' has no left operand", self.pos)
                self.pos += 1
                if self.peek() in (None, closer, "|"):
                    raise _Malformed("'|' has no right operand", self.pos - 1)
                left, right = items[-1], self.element(position)
                # One flat alternation for a|b|c (the parser never puts a modifier on it).
                choices = left.children if left.kind == "alt" else (left,)
                items[-1] = Node("alt", children=(*choices, right))
            else:
                items.append(self.element(position))
        return Node("cat", children=tuple(items))

    def element(self, position: int | None) -> Node:
        char = self.peek()
        start = self.pos
        if char in ("(", "[") and self.depth >= MAX_NESTING:
            raise _Malformed(f"groups are nested more than {MAX_NESTING} deep", start)
        self.depth += 1
        try:
            node = self.operand(char, start, position)
        finally:
            self.depth -= 1
        return self.modifier(node)

    def operand(self, char: str | None, start: int, position: int | None) -> Node:
        if char == "(":
            self.pos += 1
            node = self.sequence(")", position)
            if self.peek() != ")":
                raise _Malformed("unbalanced '(': no matching ')'", start)
            self.pos += 1
        elif char == "[":
            node = self.set_(position)
        elif char == "<":
            node = self.event()
        elif char in (")", "]", ">"):
            raise _Malformed(f"unbalanced {char!r}: nothing opens it", start)
        elif char in ("*", "+", "{", "?"):
            raise _Malformed(f"{char!r} has nothing to repeat", start)
        else:
            node = self.symbol(position)
        return node

    def symbol(self, position: int | None) -> Node:
        start = self.pos
        if self.peek() == "'":
            end = self.text.find("'", start + 1)
            if end < 0:
                raise _Malformed("unbalanced quote: the custom label has no closing '", start)
            self.pos = end + 1
            return Node("custom", self.text[start + 1 : end])
        label = self.text[start]
        self.pos += 1
        self.check_label(label, position, start)
        return Node("label", label)

    def check_label(self, label: str, position: int | None, start: int) -> None:
        if self.extended or label in self.extra_labels:
            return
        if label not in KNOWN_LABELS:
            raise _Malformed(f"unknown label {label!r}", start)
        if position is not None and position < len(_POSITION_LABELS):
            allowed, what = _POSITION_LABELS[position]
            if label not in allowed and label not in (WILDCARD, NONE_LABEL):
                raise _Malformed(
                    f"{label!r} in position {position + 1} of '<...>' must be {what}", start
                )

    def event(self) -> Node:
        start = self.pos
        if self.in_event:
            raise _Malformed("'<...>' cannot be nested inside '<...>'", start)
        self.in_event = True
        self.pos += 1
        items: list[Node] = []
        while (char := self.peek()) is not None and char != ">":
            items.append(self.element(len(items)))
        if char is None:
            raise _Malformed("unbalanced '<': no matching '>'", start)
        self.pos += 1
        self.in_event = False
        return Node("event", children=tuple(items))

    def set_(self, position: int | None) -> Node:
        start = self.pos
        self.pos += 1
        negated = self.peek() == "^"
        items: list[Node] = []
        if negated:
            self.pos += 1
            while (char := self.peek()) is not None and char != "]":
                items.append(self.symbol(position))
        else:
            while (char := self.peek()) is not None and char != "]":
                items.append(self.element(position))
        if self.peek() is None:
            raise _Malformed("unbalanced '[': no matching ']'", start)
        if negated and not items:
            raise _Malformed("the negated set '[^]' is empty", start)
        self.pos += 1
        return Node("negset" if negated else "set", children=tuple(items))

    def modifier(self, node: Node) -> Node:
        char = self.peek()
        if char not in ("*", "+", "{", "?"):
            return node
        if self.in_event:
            raise _Malformed(f"repetition {char!r} is not allowed inside '<...>'", self.pos)
        if char == "?" and not self.extended:
            raise _Malformed("'?' is not OSL LPE syntax; use {0,1}", self.pos)
        if char == "{":
            low, high = self.range_()
        else:
            self.pos += 1
            low, high = {"*": (0, _UNBOUNDED), "+": (1, _UNBOUNDED), "?": (0, 1)}[char]
        return Node(node.kind, node.text, node.children, low, high)

    def range_(self) -> tuple[int, int]:
        start = self.pos
        close = self.text.find("}", start)
        body = self.text[start + 1 : close] if close > 0 else ""
        low, comma, high = body.partition(",")
        if close < 0 or not low.isdigit() or (high and not high.isdigit()):
            raise _Malformed("malformed repetition: use {n}, {n,} or {n,m}", start)
        self.pos = close + 1
        if not comma:
            return int(low), int(low)
        if not high:
            return int(low), _UNBOUNDED
        if int(high) < int(low):
            raise _Malformed(f"malformed repetition {{{body}}}: m is less than n", start)
        return int(low), int(high)


# -- can the first event be the camera? -------------------------------------------


def _nullable(node: Node) -> bool:
    if node.min_repeat == 0:
        return True
    if node.kind == "cat":
        return all(_nullable(child) for child in node.children)
    if node.kind == "alt":
        return any(_nullable(child) for child in node.children)
    return False


def _can_start_with_camera(node: Node) -> bool:
    kind = node.kind
    if kind == "label":
        return node.text in ("C", WILDCARD) or node.text not in KNOWN_LABELS
    if kind == "custom":
        # A custom label outside '<...>' stands for any event carrying it.
        return True
    if kind == "event":
        return not node.children or _can_start_with_camera(node.children[0])
    if kind in ("set", "alt"):
        return any(_can_start_with_camera(child) for child in node.children)
    if kind == "negset":
        return all(child.text != "C" for child in node.children)
    for child in node.children:  # cat: the first element that must occur decides
        if _can_start_with_camera(child):
            return True
        if not _nullable(child):
            return False
    return False
