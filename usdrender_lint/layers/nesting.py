"""How deep a text layer (``.usda``) nests, checked before USD parses it.

usd-core 26.11's text parser recurses once per level of braces (prims,
dictionaries) and parentheses (tuples): on the 8 MB stack of a process's
main thread it overflows between 30,000 and 65,000 levels (signal 11: a run
of ``--jobs 1 --timeout 0`` died without a word), and 20,000 nested
parentheses made it allocate beyond 2 GB (100,000: 23 GB). No scene nests
anywhere near that: a layer nesting deeper than MAX_DEPTH levels is refused
with an ST001 finding instead. No pxr: the file's bytes only.
"""

from __future__ import annotations

import itertools
import os
import re

#: Levels of braces, brackets and parentheses a text layer may nest.
MAX_DEPTH = 10_000
#: What USD's grammar reads as text, not structure: strings, comments, asset
#: paths and prim paths (``</a{v=x}b>``) may hold any bracket.
_NOT_STRUCTURE = re.compile(
    rb'"""[\s\S]*?"""|\'\'\'[\s\S]*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'(?:[^\'\\\n]|\\.)*\''
    rb"|#[^\n]*|@@@[\s\S]*?@@@|@[^@\n]*@|<[^<>\n]*>"
)
#: How USD's text format starts (SdfTextFileFormat's cookie).
_TEXT_MAGIC = b"#usda"
_NOT_BRACKETS = bytes(b for b in range(256) if b not in b"{}()[]")
_NOT_OPENERS = bytes(b for b in range(256) if b not in b"{([")
#: Up to this size a text layer's openers are counted by memchr (a shot's text);
#: a larger one is mostly a mesh's tuples, an opener every dozen bytes, where
#: memchr's cost per opener passes translate's per byte.
COUNT_BY_MEMCHR = 1 << 20
_AS_PARENTHESES = bytes.maketrans(b"{[}]", b"(())")
#: Every byte but brackets and those that begin a string, comment or path.
_NOT_BRACKETS_OR_STARTS = bytes(b for b in range(256) if b not in b"{}()[]\"'#@<")
#: Rounds of removing adjacent pairs for the bound before the exact scan.
BOUND_ROUNDS = 8


def nesting_problem(path: str | os.PathLike[str], data: bytes | None = None) -> str | None:
    """Why the text layer at ``path`` nests too deeply for USD to parse (one
    line), or None: a file that is not a text layer, cannot be read, or nests
    less than MAX_DEPTH levels. ``data``: the file's bytes, when the caller
    has read them already."""
    if data is None:
        try:
            with open(path, "rb") as handle:
                data = handle.read(len(_TEXT_MAGIC))
                if data != _TEXT_MAGIC:
                    return None  # not a text layer: not read further
                data += handle.read()
        except OSError:
            return None  # USD reports what it cannot read
    if not data.startswith(_TEXT_MAGIC):
        return None
    if _too_few_openers(data):
        return None  # the cookie holds no bracket: no copy of the text without it
    # Without the cookie: the rest of its line is read as structure (its openers
    # are counted: not again).
    depth = _depth_of_many_openers(data[len(_TEXT_MAGIC) :])
    if depth < MAX_DEPTH:
        return None
    return (
        f"the file nests {depth:,} levels deep (braces, brackets or parentheses); USD's parser "
        f"overflows its stack or memory on such nesting, so at most {MAX_DEPTH:,} are read: "
        "the file is corrupt or hostile"
    )


def _too_few_openers(data: bytes) -> bool:
    """Whether ``data`` holds fewer than MAX_DEPTH braces, brackets and parentheses."""
    if len(data) < MAX_DEPTH:
        return True
    if len(data) > COUNT_BY_MEMCHR:
        return len(data.translate(None, _NOT_OPENERS)) < MAX_DEPTH
    # bytes.replace finds a single byte with memchr, from one to the next
    # (CPython's countchar, Objects/bytesobject.c), where bytes.count and
    # bytes.translate step through every byte: on a shot's 86 KB text, three
    # deletions cost half a translate that keeps only the openers.
    kept = sum(len(data.replace(opener, b"")) for opener in (b"{", b"(", b"["))
    return 3 * len(data) - kept < MAX_DEPTH


def nesting_depth(data: bytes) -> int:
    """The deepest nesting of braces, brackets and parentheses outside strings,
    comments and paths; exact from MAX_DEPTH up, else a number below it."""
    if _too_few_openers(data):
        return 0  # too few openers to nest that deep (every scene's text)
    return _depth_of_many_openers(data)


def _depth_of_many_openers(data: bytes) -> int:
    """:func:`nesting_depth` of ``data`` holding at least MAX_DEPTH openers."""
    # A bound without the costly scan for strings (2.4 ms of a 390 KB shot, a
    # third of USD's parse). Keep only brackets and the bytes that begin a
    # string, comment or path: an opener in structure is then followed by one of
    # those or by brackets in structure, so it loses an adjacent ")" only as the
    # innermost open one. A round of removing adjacent pairs lowers the depth by
    # one at most and keeps every other opener of the deepest chain: the depth is
    # at most the openers left plus the rounds. (Brackets in strings are kept
    # too; they only make the bound larger.)
    kept = data.translate(_AS_PARENTHESES, _NOT_BRACKETS_OR_STARTS)
    for rounds in range(1, BOUND_ROUNDS + 1):
        fewer = kept.replace(b"()", b"")
        if fewer.count(b"(") + rounds < MAX_DEPTH:
            return 0
        if len(fewer) == len(kept):
            break
        kept = fewer
    brackets = _NOT_STRUCTURE.sub(b"", data).translate(_AS_PARENTHESES, _NOT_BRACKETS)
    # Removing the innermost pairs lowers the depth by one at most, and what is
    # left nests at most as deep as it has openers (half its length when every
    # one is closed; all of it when none is): a mesh's million tuples end here.
    rest = brackets.replace(b"()", b"")
    if rest.count(b"(") + 1 < MAX_DEPTH:
        return 0
    steps = (1 if byte == 40 else -1 for byte in brackets)  # 40: "("
    return max(itertools.accumulate(steps), default=0)


__all__ = ["MAX_DEPTH", "nesting_depth", "nesting_problem"]
