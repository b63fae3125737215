"""Line numbers of prim and property specs in a text ``.usda`` layer.

Sdf keeps no source positions, so a small scanner over the layer text maps each
spec path (variant selections included, as ``Sdf.Spec.path`` spells them) to the
line that opens it. It only needs to be right on files Sdf parsed successfully.
"""

from __future__ import annotations

import re
from collections.abc import Iterator

#: Characters that never open or close a spec, a string, a path or a comment.
#: Runs of them (numbers, commas, "=") and of number tuples such as ``(0, 1, 0),``
#: are skipped as one token, which makes large value arrays cheap to scan.
_INERT = r"""[^\n"'@<#/{}()\[\]A-Za-z_]"""
_TOKEN = re.compile(
    r"""
    (?P<newline>\n)
  | (?P<inert>INERT+|(?:\(INERT*\)INERT*)+)
  | (?P<space>[ \t\r\f\v]+)
  | (?P<comment>\#[^\n]*|//[^\n]*|/\*.*?\*/)
  | (?P<string>\"\"\".*?\"\"\"|'''.*?'''|"(?:\\.|[^"\\\n])*"|'(?:\\.|[^'\\\n])*')
  | (?P<asset>@@@.*?@@@|@[^@\n]*@)
  | (?P<path><[^>\n]*>)
  | (?P<word>[A-Za-z_][\w:.\[\]-]*|[-+]?[0-9][\w.+-]*)
  | (?P<punct>.)
    """.replace("INERT", _INERT),
    re.VERBOSE | re.DOTALL,
)

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


#: Token kinds that may span lines (the others never hold a newline).
_MULTILINE = frozenset(("string", "comment", "asset", "inert"))
_SKIPPED = frozenset(("space", "comment", "inert"))


def _tokens(text: str) -> Iterator[tuple[str, str, int]]:
    line = 1
    for match in _TOKEN.finditer(text):
        kind = match.lastgroup or "punct"
        if kind == "newline":
            yield kind, "\n", line
            line += 1
            continue
        value = match.group()
        if kind not in _SKIPPED:
            yield kind, value, line
        if kind in _MULTILINE:
            line += value.count("\n")


def _unquote(token: str) -> str:
    for quote in ('"""', "'''", '"', "'"):
        if token.startswith(quote) and token.endswith(quote) and len(token) >= 2 * len(quote):
            return token[len(quote) : -len(quote)]
    return token


def index_usda(text: str) -> dict[str, int]:
    """Map spec paths (``/A/B``, ``/A{v=x}B.attr``) to 1-based line numbers."""
    lines: dict[str, int] = {}
    # Each frame: (kind, path) with kind in prim | variantset | variant | other.
    stack: list[tuple[str, str]] = [("prim", "")]
    parens = 0  # metadata and value parentheses/brackets: no statements inside
    statement: list[tuple[str, str, int]] = []
    pending: tuple[str, str] | None = None  # a frame the next "{" opens

    def prim_path(parent: str, name: str) -> str:
        # Inside a variant Sdf spells the child right after the selection: /A{v=x}B
        return parent + name if parent.endswith("}") else parent + "/" + name

    def flush_statement() -> None:
        # A statement in a prim body: a property declaration opens its spec.
        words = [v for k, v, _ in statement if k == "word"]
        if not statement or stack[-1][0] not in ("prim", "variant") or not stack[-1][1]:
            return
        if statement[0][0] != "word" or words[0] in _PRIM_SPECIFIERS or words[0] == "variantSet":
            return
        rest = [w for w in words if w not in _PROPERTY_QUALIFIERS]
        if len(rest) < 2:
            return
        name = rest[1].split(".")[0]
        path = stack[-1][1] + "." + name
        lines.setdefault(path, statement[0][2])

    tokens = list(_tokens(text))
    i = 0
    while i < len(tokens):
        kind, value, line = tokens[i]
        i += 1
        if parens:
            if value in "([":
                parens += 1
            elif value in ")]":
                parens -= 1
            continue
        if kind == "newline":
            flush_statement()
            statement = []
            continue
        if statement and kind != "punct":
            # Inside a statement only brackets and braces change the structure.
            statement.append((kind, value, line))
            continue
        top_kind, top_path = stack[-1]
        if (
            not statement
            and kind == "word"
            and value in _PRIM_SPECIFIERS
            and top_kind in ("prim", "variant")
        ):
            # def [Type] "name": the name is the first string token.
            j = i
            while j < len(tokens) and tokens[j][0] == "word":
                j += 1
            if j < len(tokens) and tokens[j][0] == "string":
                path = prim_path(top_path, _unquote(tokens[j][1]))
                lines.setdefault(path, line)
                pending = ("prim", path)
                statement = [(kind, value, line)]
                i = j + 1
                continue
        opens_variant_set = (
            not statement
            and kind == "word"
            and value == "variantSet"
            and top_kind in ("prim", "variant")
            and i < len(tokens)
            and tokens[i][0] == "string"
        )
        if opens_variant_set:
            pending = ("variantset", top_path + "{" + _unquote(tokens[i][1]) + "=")
        if top_kind == "variantset" and kind == "string" and not statement:
            pending = ("variant", top_path + _unquote(value) + "}")
        if value == "{":
            flush_statement()
            if pending is not None:
                stack.append(pending)
                pending = None
            else:
                stack.append(("other", top_path))
            statement = []
            continue
        if value == "}":
            if len(stack) > 1:
                stack.pop()
            statement = []
            continue
        if value in "([":
            parens += 1
        statement.append((kind, value, line))
    flush_statement()
    return lines


_CACHE: dict[str, dict[str, int]] = {}


def line_of(layer_path: str, spec_path: str) -> int | None:
    """The line of ``spec_path`` in the text layer at ``layer_path``, if found."""
    index = _CACHE.get(layer_path)
    if index is None:
        try:
            with open(layer_path, encoding="utf-8", errors="replace") as handle:
                index = index_usda(handle.read())
        except OSError:
            index = {}
        _CACHE[layer_path] = index
    return index.get(spec_path)


def clear_cache() -> None:
    _CACHE.clear()


def comment_lines(text: str) -> list[int]:
    """The lines where a ``#``, ``//`` or ``/* */`` comment starts, the ``#usda``
    header excepted: what Sdf drops when it saves the layer again."""
    found = []
    line = 1
    for match in _TOKEN.finditer(text):
        value = match.group()
        if match.lastgroup == "comment" and match.start() != 0:
            found.append(line)
        line += value.count("\n")
    return found
