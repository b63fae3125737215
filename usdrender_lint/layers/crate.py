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
states more is corrupt, whatever USD would do with it. No pxr: the file's
bytes only, a few dozen of them.
"""

from __future__ import annotations

import os
import struct

MAGIC = b"PXR-USDC"
#: The bootstrap: magic, version (8 bytes), table of contents offset (int64).
_BOOTSTRAP = 24
#: A table of contents entry: a 16-byte name, start and size (int64 each).
_SECTION = 32
#: The structural sections, each led by its item count (uint64).
_COUNTED = ("TOKENS", "STRINGS", "FIELDS", "FIELDSETS", "PATHS", "SPECS")
#: Items a byte of a section can hold at most (see above), with room to spare.
ITEMS_PER_BYTE = 1024


def crate_structure_problem(path: str | os.PathLike[str]) -> str | None:
    """Why the crate at ``path`` is corrupt (one line), or None: a file that
    is not a crate, that cannot be read, or whose structure is consistent."""
    try:
        with open(path, "rb") as handle:
            size = os.fstat(handle.fileno()).st_size
            head = handle.read(_BOOTSTRAP)
            if len(head) < _BOOTSTRAP or head[:8] != MAGIC:
                return None
            return _structure_problem(handle, size, head)
    except OSError:
        return None  # USD reports what it cannot read


def is_crate(path: str | os.PathLike[str]) -> bool:
    """Whether the file at ``path`` starts as a crate does."""
    try:
        with open(path, "rb") as handle:
            return handle.read(len(MAGIC)) == MAGIC
    except OSError:
        return False


def _structure_problem(handle, size: int, head: bytes) -> str | None:  # noqa: ANN001
    (toc,) = struct.unpack("<q", head[16:24])
    if not _BOOTSTRAP <= toc <= size - 8:
        return (
            f"the crate's table of contents is at byte {toc:,} but the file has {size:,} bytes: "
            "the file is corrupt, possibly truncated"
        )
    (count,) = struct.unpack("<Q", _read(handle, toc, 8))
    room = (size - toc - 8) // _SECTION
    if count > room:
        return (
            f"the crate's table of contents lists {count:,} sections where the file has room "
            f"for {room:,}: the file is corrupt"
        )
    entries = _read(handle, toc + 8, count * _SECTION)
    for index in range(count):
        raw_name, start, length = struct.unpack_from("<16sqq", entries, index * _SECTION)
        name = raw_name.split(b"\0", 1)[0].decode("ascii", "replace")
        if start < 0 or length < 0 or start + length > size:
            return (
                f"the crate's {name} section (bytes {start:,} to {start + length:,}) lies "
                f"outside the {size:,}-byte file: the file is corrupt"
            )
        if name not in _COUNTED or length < 8:
            continue
        # PATHS states its count twice (all paths, then those encoded).
        words = 2 if name in ("PATHS", "TOKENS") and length >= 16 else 1
        for stated in struct.unpack(f"<{words}Q", _read(handle, start, 8 * words)):
            if stated > ITEMS_PER_BYTE * length + ITEMS_PER_BYTE:
                return (
                    f"the crate's {name} section states {stated:,} items in {length:,} bytes, "
                    "more than they can hold: the file is corrupt"
                )
    return None


def _read(handle, offset: int, length: int) -> bytes:  # noqa: ANN001
    handle.seek(offset)
    data = handle.read(length)
    if len(data) < length:
        raise OSError("short read")
    return data


__all__ = ["MAGIC", "crate_structure_problem", "is_crate"]
