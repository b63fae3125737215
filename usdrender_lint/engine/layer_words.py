"""Which words a layer file can hold, read from its bytes without USD.

Some of the engine's work is needed only when a layer authors a certain field
or key anywhere: customData suppressions (``usdrender_lint``), value clips
(``clips``), references and payloads (``references``, ``payload``). Asking USD
means visiting every spec (``GetCompositionAssetDependencies`` walks them all;
reading a suppression means one metadata read per prim). The file itself
answers for less:

- a text layer (``#usda``) holds a word when its bytes do; a backslash anywhere
  means a quoted string may spell it with escapes, so every word may be there;
- a crate (``.usdc``) names every field, key, type, prim, property and string
  through its TOKENS section, so a word that is not a token is nowhere in it.
  The section is LZ4 compressed (usd-core's TfFastCompression, pxr/base/tf/
  fastCompression.cpp; the layout is read in pxr/usd/sdf/crateFile.cpp,
  ``CrateFile::_ReadTokens``): a small pure-Python decoder reads it.

Anything else (a package, another file format, a crate version this module
does not know, a section that does not decode to exactly what it declares)
answers "may hold every word", so a caller only ever skips work that provably
finds nothing.
"""

from __future__ import annotations

import os
import struct
from collections.abc import Collection, Iterable
from typing import TYPE_CHECKING, NamedTuple

from ..layers.crate import crate_sections, fast_decompress
from ..layers.files import layer_real_path

if TYPE_CHECKING:
    from pxr import Sdf

USDA_MAGIC = b"#usda "
CRATE_MAGIC = b"PXR-USDC"
#: Crate versions whose TOKENS section is compressed (0.4.0 on) and that this
#: reader was checked against (usd-core 26.11 writes 0.8.0 by default).
MIN_CRATE, MAX_CRATE = (0, 4, 0), (0, 99, 99)
#: Largest TOKENS section decoded (larger ones: "may hold anything").
MAX_TOKEN_BYTES = 64 << 20
#: About how many bytes of usda text one spec takes (for spec_count's estimate).
TEXT_BYTES_PER_SPEC = 60


#: The words callers ask about (each answer is computed once per file version).
WORDS = (
    "references",
    "payload",
    "inheritPaths",
    "specializes",
    "relocates",
    "subLayers",
    "clips",
    "usdrender_lint",
    "untyped",
    # A crate's field for a prim's variant sets (partial.py checks their names).
    "variantSetChildren",
    # Fields of varying values (resolve.PrimValues asks no spec for them without).
    "timeSamples",
    "spline",
    # Layer metadata the fast path looks for in value clip layers (partial.py).
    "renderSettingsPrimPath",
)
#: Fields usda spells with another keyword (``inherits = </Class>``, ``variantSet "v" = {``).
TEXT_SPELLING = {"inheritPaths": "inherits", "variantSetChildren": "variantSet"}
#: Answers kept per process, keyed by the file's path and version.
_MEMO_SIZE = 256
_Key = tuple[str, int, int, int]
_memo: dict[_Key, _Scan] = {}
#: A text layer's words are searched for when first asked (each search reads
#: the whole file; a lint asks for two or three of the ten), so the bytes of
#: the last text layer read are kept for the next question, up to this size.
MAX_HELD_TEXT = 4 << 20
_held_text: tuple[_Key, bytes] | None = None


class _Scan(NamedTuple):
    #: "text", "crate" or "unknown" (may hold anything).
    kind: str
    #: The WORDS it holds, and "@" for a text layer with asset paths.
    words: frozenset[str]
    #: Its specs: a crate's count, a text layer's estimate; None when unknown.
    specs: int | None
    #: The WORDS a text layer's bytes were not searched for yet.
    unsearched: frozenset[str] = frozenset()


_UNKNOWN = _Scan("unknown", frozenset(), None)


def may_hold(path: str, words: Collection[str]) -> set[str]:
    """The ``words`` (of WORDS) the layer file at ``path`` may hold (all of
    them unless the file proves otherwise)."""
    key = _key(path)
    scan = _UNKNOWN if key is None else _scan(key)
    missing = scan.unsearched.intersection(words)
    if key is not None and missing:
        scan = _search(key, scan, missing)
    if scan.kind == "unknown":
        return set(words)
    return {w for w in words if w in scan.words}


def layers_may_hold(layers: Iterable[Sdf.Layer], word: str) -> bool:
    """Whether any of the layers may author ``word`` (of WORDS)."""
    return bool(words_layers_may_hold(layers, (word,)))


def words_layers_may_hold(layers: Iterable[Sdf.Layer], words: Collection[str]) -> set[str]:
    """The ``words`` (of WORDS) some of the layers may author, each layer's
    file looked at once for all of them. A layer with unsaved edits, an
    anonymous layer with specs (a session layer holding more than variant
    selections) or one that is not a plain file may hold any word."""
    held: set[str] = set()
    for layer in layers:
        if layer.anonymous:
            if layer.rootPrims and not holds_only_selections(layer):
                return set(words)
            continue
        path = layer_real_path(layer)
        if layer.dirty or not path:
            return set(words)
        held |= may_hold(path, [word for word in words if word not in held])
        if len(held) == len(words):
            break
    return held


#: The only fields of a prim spec that holds a variant selection and nothing else.
_SELECTION_FIELDS = frozenset(("specifier", "variantSelection"))


def holds_only_selections(layer: Sdf.Layer) -> bool:
    """True when every prim spec of ``layer`` is an ``over`` with no fields but
    variant selections and no properties (what --variants authors in a session
    layer): such a layer authors none of the WORDS, whatever it selects."""
    pending = list(layer.rootPrims)
    while pending:
        spec = pending.pop()
        if spec.properties or not _SELECTION_FIELDS.issuperset(spec.ListInfoKeys()):
            return False
        if spec.specifier != _over():
            return False
        pending.extend(spec.nameChildren)
    return True


def _over():
    from pxr import Sdf  # a layer already exists: pxr is imported

    return Sdf.SpecifierOver


def without_external_arcs(path: str) -> bool:
    """True when the layer file provably has no sublayer, reference or payload
    (a text layer with no ``@``: usda writes every asset path between them)."""
    key = _key(path)
    scan = _UNKNOWN if key is None else _scan(key)
    if scan.kind == "text":
        return "@" not in scan.words
    return scan.kind == "crate" and not scan.words.intersection(
        ("references", "payload", "subLayers")
    )


def is_text_file(path: str) -> bool:
    """Whether the file at ``path`` is a text layer (it begins ``#usda``)."""
    key = _key(path)
    return key is not None and _scan(key).kind == "text"


def spec_count(path: str) -> int | None:
    """How many specs the layer file holds: a crate says so in its SPECS
    section; for a text layer, an estimate from its size; None otherwise."""
    key = _key(path)
    return None if key is None else _scan(key).specs


def _key(path: str) -> _Key | None:
    """The file's path and version (None when it cannot be read)."""
    try:
        info = os.stat(path)
    except OSError:
        return None
    return (path, info.st_size, info.st_mtime_ns, info.st_ino)


def _scan(key: _Key) -> _Scan:
    answer = _memo.get(key)
    if answer is None:
        answer = _read(key)
        _remember(key, answer)
    return answer


def _remember(key: _Key, answer: _Scan) -> None:
    if key not in _memo and len(_memo) >= _MEMO_SIZE:
        _memo.clear()
    _memo[key] = answer


def _search(key: _Key, scan: _Scan, words: Collection[str], data: bytes | None = None) -> _Scan:
    """``scan`` with ``words`` searched for in a text layer's bytes (``data``,
    else the bytes kept of the last text layer read, else the file's)."""
    if data is None and _held_text is not None and _held_text[0] == key:
        data = _held_text[1]
    if data is None:
        try:
            with open(key[0], "rb") as handle:
                data = handle.read()
        except OSError:
            data = b""
        if len(data) != key[1]:  # changed since it was first read: may hold anything
            return _UNKNOWN
    # rfind, not ``in``: the same answer, but CPython's backward search skips through
    # usda text where its forward one mostly steps a byte at a time (a word that is
    # not in a 86 KB shot: "clips" 120 us against 20, "spline" 150 against 17).
    held = {w for w in words if data.rfind(TEXT_SPELLING.get(w, w).encode()) != -1}
    answer = scan._replace(words=scan.words | held, unsearched=scan.unsearched.difference(words))
    _remember(key, answer)
    return answer


def text_bytes(path: str) -> bytes | None:
    """The bytes of the text layer (``#usda``) at ``path``, or None for any
    other file or one that cannot be read. Read once per file version: the
    engine checks them before USD reads the file (layers/nesting.py), and
    :func:`may_hold` answers from the same bytes (no second read)."""
    global _held_text
    key = _key(path)
    if key is None:
        return None
    if _held_text is not None and _held_text[0] == key:
        return _held_text[1]
    try:
        # Unbuffered, and read again from its start: the bytes are not copied
        # (a buffered read and ``head + rest`` copied the whole file twice).
        with open(path, "rb", buffering=0) as handle:
            if handle.read(len(USDA_MAGIC)) != USDA_MAGIC:
                return None  # a crate is never read whole here
            handle.seek(0)
            data = handle.readall()
    except OSError:
        return None
    if len(data) != key[1]:
        return None  # changed since it was looked at: read as any other file
    if key not in _memo:
        _remember(key, _text_scan(key, data))
    elif len(data) <= MAX_HELD_TEXT:
        _held_text = (key, data)  # scanned in an earlier lint: its unsearched words
    return data


def _read(key: _Key) -> _Scan:
    path = key[0]
    try:
        with open(path, "rb") as handle:
            head = handle.read(16)
            if head.startswith(CRATE_MAGIC):
                tokens, specs = _crate_tokens(handle, head)
                if tokens is None:
                    return _UNKNOWN
                return _Scan("crate", frozenset(w for w in WORDS if w in tokens), specs)
            if head.startswith(USDA_MAGIC):
                return _text_scan(key, head + handle.read())
    except (OSError, struct.error, ValueError):
        pass  # unreadable, or a crate cut short: may hold anything
    return _UNKNOWN


def _text_scan(key: _Key, data: bytes) -> _Scan:
    """The scan of a text layer's bytes ``data``; they are kept for the words
    asked next when not too large."""
    global _held_text
    at = {"@"} if b"@" in data else set()
    specs = len(data) // TEXT_BYTES_PER_SPEC
    if b"\\" in data:  # a quoted string may spell any word with escapes
        return _Scan("text", frozenset(WORDS) | at, specs)
    scan = _Scan("text", frozenset(at), specs, frozenset(WORDS))
    if len(data) > MAX_HELD_TEXT:
        return _search(key, scan, WORDS, data)  # every word now, not keep the bytes
    _held_text = (key, data)
    return scan


def _crate_tokens(handle, head: bytes) -> tuple[set[str] | None, int | None]:  # noqa: ANN001
    """Every token of a crate file (None when it cannot be read for sure) and
    the number of specs it declares (pxr/usd/sdf/crateFile.cpp, _ReadSpecs)."""
    if len(head) < 16 or not MIN_CRATE <= tuple(head[8:11]) <= MAX_CRATE:
        return None, None
    sections = crate_sections(handle, head + handle.read(8))
    if sections is None:
        return None, None
    specs = _spec_count(handle, *sections.get("SPECS", (0, 0)))
    return _tokens(handle, *sections.get("TOKENS", (0, 0))), specs


def _spec_count(handle, start: int, end: int) -> int | None:  # noqa: ANN001
    if not 0 < start < end:
        return None
    handle.seek(start)
    return struct.unpack("<Q", handle.read(8))[0]


def _tokens(handle, start: int, end: int) -> set[str] | None:  # noqa: ANN001
    """The tokens of a TOKENS section: a count, the size of their NUL-ended
    names and of those compressed, then the compressed names."""
    if not 0 < start < end:
        return None
    handle.seek(start)
    num_tokens, raw_size, packed_size = struct.unpack("<QQQ", handle.read(24))
    if raw_size > MAX_TOKEN_BYTES or packed_size > end - start - 24 or packed_size < 1:
        return None
    raw = fast_decompress(handle.read(packed_size), raw_size)
    if raw is None or len(raw) != raw_size or raw.count(0) != num_tokens or raw[-1:] != b"\0":
        return None
    try:
        return set(raw[:-1].decode("utf-8").split("\0"))
    except UnicodeDecodeError:
        return None


__all__ = [
    "WORDS",
    "holds_only_selections",
    "layers_may_hold",
    "may_hold",
    "spec_count",
    "text_bytes",
    "without_external_arcs",
    "words_layers_may_hold",
]
