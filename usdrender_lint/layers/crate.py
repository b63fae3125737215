"""A crate (``.usdc``) file's structure checked before USD reads it.

USD's crate reader trusts the counts a file states: the table of contents'
section count and each structural section's leading item count (tokens,
strings, fields, field sets, paths, specs; ``pxr/usd/sdf/crateFile.cpp``,
``_ReadStructuralSections``). One flipped bit in a count made usd-core 26.11
allocate and loop for minutes (a 1 KB file: 227 s and 11.8 GB) before failing.
Every count is checked here against what its bytes can hold: an item takes at
least 2 bits before LZ4 compression (Sdf's integer coding), and LZ4 expands
at most 255 times, so a section of ``n`` bytes holds at most ``1020 n`` items
(uncompressed sections hold whole items of 4 bytes or more). A file that
states more is corrupt, whatever USD would do with it.

USD trusts the indexes those sections hold too: a spec's type is checked
by :func:`crate_spec_problem`.
No pxr: the file's bytes only.
"""

from __future__ import annotations

import os
import struct
from functools import cache
from itertools import compress

MAGIC = b"PXR-USDC"
#: The bootstrap: magic, version (8 bytes), table of contents offset (int64).
_BOOTSTRAP = 24
#: A table of contents entry: a 16-byte name, start and size (int64 each).
_SECTION = 32
#: The structural sections, each led by its item count (uint64).
_COUNTED = ("TOKENS", "STRINGS", "FIELDS", "FIELDSETS", "PATHS", "SPECS")
#: Items a byte of a section can hold at most (see above), with room to spare.
ITEMS_PER_BYTE = 1024


class _Corrupt(Exception):
    """The file's structure is inconsistent (the message says how)."""


def crate_structure_problem(path: str | os.PathLike[str]) -> str | None:
    """Why the crate at ``path`` is corrupt (one line), or None: a file that
    is not a crate, that cannot be read, or whose structure is consistent."""
    try:
        with open(path, "rb") as handle:
            size = os.fstat(handle.fileno()).st_size
            head = handle.read(_BOOTSTRAP)
            if len(head) < _BOOTSTRAP or head[:8] != MAGIC:
                return None
            _check_counts(handle, _sections(handle, size, head))
    except OSError:
        return None  # USD reports what it cannot read
    except _Corrupt as exc:
        return str(exc)
    return None


def is_crate(path: str | os.PathLike[str]) -> bool:
    """Whether the file at ``path`` starts as a crate does."""
    try:
        with open(path, "rb") as handle:
            return handle.read(len(MAGIC)) == MAGIC
    except OSError:
        return False


def crate_sections(handle, head: bytes) -> dict[str, tuple[int, int]] | None:  # noqa: ANN001
    """Each section's (start, end) by name, of the crate open as ``handle``
    whose first 24 bytes are ``head``; None when they are not all in the file."""
    try:
        return _sections(handle, os.fstat(handle.fileno()).st_size, head)
    except (_Corrupt, OSError):
        return None


def _sections(handle, size: int, head: bytes) -> dict[str, tuple[int, int]]:  # noqa: ANN001
    """Each section's (start, end) by name, in the file; raises _Corrupt."""
    (toc,) = struct.unpack("<q", head[16:24])
    if not _BOOTSTRAP <= toc <= size - 8:
        raise _Corrupt(
            f"the crate's table of contents is at byte {toc:,} but the file has {size:,} bytes: "
            "the file is corrupt, possibly truncated"
        )
    (count,) = struct.unpack("<Q", _read(handle, toc, 8))
    room = (size - toc - 8) // _SECTION
    if count > room:
        raise _Corrupt(
            f"the crate's table of contents lists {count:,} sections where the file has room "
            f"for {room:,}: the file is corrupt"
        )
    sections: dict[str, tuple[int, int]] = {}
    for raw_name, start, length in struct.iter_unpack(
        "<16sqq", _read(handle, toc + 8, count * _SECTION)
    ):
        name = raw_name.split(b"\0", 1)[0].decode("ascii", "replace")
        if start < 0 or length < 0 or start + length > size:
            raise _Corrupt(
                f"the crate's {name} section (bytes {start:,} to {start + length:,}) lies "
                f"outside the {size:,}-byte file: the file is corrupt"
            )
        sections.setdefault(name, (start, start + length))  # USD reads the first of a name
    return sections


def _check_counts(handle, sections: dict[str, tuple[int, int]]) -> None:  # noqa: ANN001
    for name in _COUNTED:
        start, end = sections.get(name, (0, 0))
        length = end - start
        if length < 8:
            continue
        # PATHS states its count twice (all paths, then those encoded).
        words = 2 if name in ("PATHS", "TOKENS") and length >= 16 else 1
        for stated in struct.unpack(f"<{words}Q", _read(handle, start, 8 * words)):
            if stated > ITEMS_PER_BYTE * length + ITEMS_PER_BYTE:
                raise _Corrupt(
                    f"the crate's {name} section states {stated:,} items in {length:,} bytes, "
                    "more than they can hold: the file is corrupt"
                )


def _read(handle, offset: int, length: int) -> bytes:  # noqa: ANN001
    handle.seek(offset)
    data = handle.read(length)
    if len(data) < length:
        raise OSError("short read")
    return data


# -- the specs' types -------------------------------------------------------------
#
# USD trusts the indexes a crate's tables hold (CrateFile::_ReadStructuralSections
# range-checks them only when built "safety over speed", which usd-core is not).
# It follows each spec's path and field set while it opens the layer, so a bad one
# fails (or crashes) the open itself, before any rule. A spec's type it only stores:
# Sdf reads it when a handle to the spec is made (a rule reading a property stack,
# after the open), and an invalid one crashed usd-core 26.11 there. So the types
# are checked here, decoded (Sdf's integer coding, pxr/usd/sdf/integerCoding.cpp,
# under LZ4) only as far as their extremes: the types change at a few deltas only
# (a crate lists its specs type by type), and a run of the common delta moves the
# value steadily, so its ends bound it.

#: Sdf's spec types (SdfSpecType): 1 (attribute) to 11 (variant set); 0 is unknown.
SPEC_TYPES = range(1, 12)
#: The crate version from which the SPECS tables are compressed (older crates
#: are not checked here).
_COMPRESSED = (0, 4, 0)
#: The struct codes of the integer coding's 2-bit kinds (32-bit tables): the
#: common delta (no bytes), an int8, an int16, an int32.
_KIND_CODES = ("", "b", "h", "i")


@cache
def _code_tables() -> tuple[tuple[str, ...], tuple[tuple[int, ...], ...]]:
    """Per code byte (the kinds of four integers): the struct codes of its deltas,
    and the slots (0 to 3) whose delta is not the common one. Made at the first
    crate read (3.6M instructions), not at every start-up: a text layer needs none."""
    formats = tuple(
        "".join(_KIND_CODES[(byte >> shift) & 3] for shift in (0, 2, 4, 6)) for byte in range(256)
    )
    slots = tuple(
        tuple(slot for slot in range(4) if (byte >> (2 * slot)) & 3) for byte in range(256)
    )
    return formats, slots


class _Unreadable(Exception):
    """A table's deltas run past its data: USD reads the rest from memory that
    is not the table's (no error, and then a crash)."""


def crate_spec_problem(path: str | os.PathLike[str]) -> str | None:
    """Why USD cannot read the specs of the crate at ``path`` once it has
    opened it ("a spec of no valid type"), or None: also for a file that is
    not a crate or cannot be read, a crate older than 0.4.0, and a table USD
    cannot decompress either (it says so when it opens the file)."""
    try:
        with open(path, "rb") as handle:
            size = os.fstat(handle.fileno()).st_size
            head = handle.read(_BOOTSTRAP)
            if len(head) < _BOOTSTRAP or head[:8] != MAGIC or tuple(head[8:11]) < _COMPRESSED:
                return None
            start, end = _sections(handle, size, head).get("SPECS", (0, 0))
            specs = _read(handle, start, end - start) if end - start >= 8 else b""
        types = _spec_types(specs)
    except (OSError, struct.error, _Corrupt):
        return None
    except _Unreadable:
        return "a spec of no valid type"  # USD reads the types from memory past the table
    if types is not None and not (SPEC_TYPES.start <= types[0] and types[1] < SPEC_TYPES.stop):
        return "a spec of no valid type"
    return None


def _spec_types(specs: bytes) -> tuple[int, int] | None:
    """The least and greatest spec type of a SPECS section (None: no specs, or
    a table USD cannot decompress either): a spec count, then three tables of
    that many compressed integers (paths, field sets, types), each a uint64
    size and TfFastCompression data."""
    count = struct.unpack_from("<Q", specs)[0] if specs else 0
    pos = 8
    for _ in range(2):  # the paths and field sets: read while USD opens the layer
        pos += 8 + struct.unpack_from("<Q", specs, pos)[0]
        if pos > len(specs):  # a size past the section (too large for an index, even)
            return None
    if not count:
        return None
    (packed,) = struct.unpack_from("<Q", specs, pos)
    codes_size = (count * 2 + 7) // 8
    raw = fast_decompress(specs[pos + 8 : pos + 8 + packed], 4 + codes_size + 4 * count)
    return None if raw is None else _coded_extremes(raw, count, codes_size)


def _coded_extremes(raw: bytes, count: int, codes_size: int) -> tuple[int, int]:
    """The extremes of ``count`` integers in Sdf's integer coding: the common
    delta (int32), a 2-bit kind per integer, then the other deltas in order."""
    if len(raw) < 4 + codes_size:
        raise _Unreadable
    (common,) = struct.unpack_from("<i", raw)
    codes = raw[4 : 4 + codes_size]
    if count % 4:  # the last code byte's unused kinds are not read
        codes = codes[:-1] + bytes([codes[-1] & ((1 << (2 * (count % 4))) - 1)])
    uncommon = list(compress(range(codes_size), codes))  # the code bytes with another delta
    code_formats, uncommon_slots = _code_tables()
    fmt = "<" + "".join([code_formats[codes[index]] for index in uncommon])
    if struct.calcsize(fmt) > len(raw) - 4 - codes_size:
        raise _Unreadable
    deltas = struct.unpack_from(fmt, raw, 4 + codes_size)
    positions = [4 * index + slot for index in uncommon for slot in uncommon_slots[codes[index]]]
    bounds: list[int] = []
    value, last = 0, -1
    for position, delta in zip(positions, deltas, strict=True):
        bounds += _run(value, common, position - last - 1)
        value += common * (position - last - 1) + delta
        bounds.append(value)
        last = position
    bounds += _run(value, common, count - last - 1)
    return min(bounds), max(bounds)


def _run(value: int, common: int, length: int) -> tuple[int, ...]:
    """The extremes of ``length`` steps of ``common`` from ``value`` (its ends)."""
    return (value + common, value + common * length) if length > 0 else ()


# -- LZ4 ----------------------------------------------------------------------------


def fast_decompress(data: bytes, size: int) -> bytes | None:
    """TfFastCompression's data (at most ``size`` bytes once decompressed), or
    None when it does not decode: a chunk count byte (0: one LZ4 block
    follows), else that many chunks, each an int32 size and an LZ4 block."""
    if not data:
        return None
    if data[0] == 0:
        return lz4_block(data, 1, len(data), size)
    out = bytearray()
    pos = 1
    for _ in range(data[0]):
        if pos + 4 > len(data):
            return None
        (chunk,) = struct.unpack_from("<i", data, pos)
        pos += 4
        block = lz4_block(data, pos, pos + chunk, size - len(out))
        if block is None:
            return None
        out += block
        pos += chunk
    return bytes(out)


def lz4_block(data: bytes, pos: int, stop: int, limit: int) -> bytes | None:
    """Decode one LZ4 block (the public block format: sequences of a token,
    literals and a back-reference) of at most ``limit`` bytes."""
    out = bytearray()
    try:
        while pos < stop:
            token = data[pos]
            literals, pos = _length(data, pos + 1, token >> 4)
            out += data[pos : pos + literals]
            pos += literals
            if pos >= stop:
                break  # the last sequence has literals only
            offset = data[pos] | (data[pos + 1] << 8)
            length, pos = _length(data, pos + 2, token & 15)
            if not _copy_match(out, offset, length + 4, limit):
                return None
    except IndexError:
        return None
    return bytes(out) if len(out) <= limit else None


def _length(data: bytes, pos: int, length: int) -> tuple[int, int]:
    """A sequence's length from its 4-bit nibble (15: more bytes follow, each
    added, until one is not 255), and the position after it."""
    if length == 15:
        while True:
            extra = data[pos]
            pos += 1
            length += extra
            if extra != 255:
                break
    return length, pos


def _copy_match(out: bytearray, offset: int, length: int, limit: int) -> bool:
    """Append the back-reference's bytes; False when it points before the
    output or runs past ``limit``."""
    begin = len(out) - offset
    if offset == 0 or begin < 0 or len(out) + length > limit:
        return False
    if offset >= length:
        out += out[begin : begin + length]
    else:  # the match overlaps what it writes: repeat the period
        out += (out[begin:] * (length // offset + 1))[:length]
    return True


__all__ = [
    "MAGIC",
    "crate_structure_problem",
    "crate_sections",
    "crate_spec_problem",
    "fast_decompress",
    "is_crate",
    "lz4_block",
]
