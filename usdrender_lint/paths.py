"""How paths are shown: relative to the working directory when below it, the
file on disk behind a layer identifier, and names that are not UTF-8 in an
escaped form any output can carry (no pxr)."""

from __future__ import annotations

import os
import re
import sys
import unicodedata
from pathlib import Path


def layer_file(identifier: str | None) -> Path | None:
    """The file on disk behind a layer identifier: a layer inside a ``.usdz``
    (``pkg.usdz[inner.usda]``) is the package; anonymous layers have none.
    Absolute, with symbolic links not followed: every format names the file
    as the JSON report does (:func:`display_path`), as the user named it."""
    if not identifier or identifier.startswith("anon:"):
        return None
    if identifier.endswith("]") and "[" in identifier:
        identifier = identifier[: identifier.index("[")]
    try:
        return Path(os.path.abspath(identifier))
    except OSError:  # the working directory is gone, or too long to name
        return Path(identifier)


def display_path(path: str | None, base: str | None = None) -> str:
    """A path relative to ``base`` (the working directory by default) when it
    is below it. Symbolic links are not followed: a link is named as the user
    named it."""
    if not path:
        return ""
    try:
        cwd = os.getcwd()
    except OSError:  # the working directory is gone, or too long to name
        return path
    absolute = os.path.abspath(os.path.join(cwd, path))
    prefix = (base or cwd).rstrip(os.sep) + os.sep
    return absolute[len(prefix) :] if absolute.startswith(prefix) else path


def tidy(path: str) -> str:
    """``path`` without its ``.`` components and repeated separators
    (``./shots//a.usda``: ``shots/a.usda``), as ruff names the files of
    ``ruff check .``. ``..`` stays: through a symbolic link it is not the
    parent's parent."""
    if os.sep + "." not in os.sep + path and os.sep * 2 not in path:
        return path
    root = os.sep if path.startswith(os.sep) else ""
    return root + os.sep.join(p for p in path.split(os.sep) if p not in ("", ".")) or "."


def repository_root() -> str | None:
    """The root of the Git work tree the working directory is in (the nearest
    folder up holding ``.git``), or None outside one: what code scanning and
    GitLab read a report's relative paths against."""
    try:
        folder = os.getcwd()
    except OSError:
        return None
    while not os.path.exists(os.path.join(folder, ".git")):
        parent = os.path.dirname(folder)
        if parent == folder:
            return None
        folder = parent
    return folder


def relative_in(text: str, cwd: str | None = None) -> str:
    """``text`` (a message) with each absolute path below the working
    directory written relative to it, as the report names files: USD's
    messages quote absolute paths (``@/ci/runner/work/shot.usda@``), which
    would carry the machine's folders into annotations."""
    try:
        cwd = cwd or os.getcwd()
    except OSError:
        return text
    prefix = cwd.rstrip(os.sep) + os.sep
    if prefix == os.sep or prefix not in text:
        return text
    import re

    # Only where a path starts: not inside a longer path (/x/work/ for /work/).
    return re.sub(r"(?<![\w./~-])" + re.escape(prefix), "", text)


def escape(text: str) -> str:
    """``text`` as valid UTF-8 text, losslessly. A file name that is not UTF-8
    reaches Python with each undecodable byte held as a surrogate escape, which
    no UTF-8 output (a terminal, JSON, SARIF) can carry: such bytes are written
    ``\\xNN`` and, in such a text only, a backslash is doubled, so the bytes
    can be recovered. Valid text is returned as it is."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        raw = text.encode("utf-8", "surrogateescape").replace(b"\\", b"\\\\")
        return raw.decode("utf-8", "backslashreplace")
    return text


#: Characters no printed line carries as they are: C0 and C1 controls and DEL
#: (a layer's token value could move the cursor, colour or retitle a terminal,
#: or start a forged report line), Unicode line and paragraph separators, and
#: the bidirectional controls that reorder what a reader sees ("Trojan Source").
_UNPRINTABLE = "\x00-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028\u2029\u202a-\u202e\u2066-\u2069"
_SHORT = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}
_PATTERNS: dict[str, re.Pattern[str]] = {}
#: Characters of a message, a path or an error printed for a person (text,
#: GitHub annotations, SARIF, stderr) at most; the JSON report keeps it whole.
PRINT_LIMIT = 2000


def printable(text: str, keep: str = "", limit: int | None = PRINT_LIMIT) -> str:
    """``text`` as a printed line may carry it: :func:`escape` d, with every
    control character but those in ``keep`` written ``\\n``, ``\\x1b`` or
    ``\\u202e``, and cut at ``limit`` characters (saying how long it was)."""
    pattern = _PATTERNS.get(keep)
    if pattern is None:
        kept = "".join(f"\\x{ord(c):02x}" for c in keep)
        body = f"[{_UNPRINTABLE}]" if not kept else f"(?![{kept}])[{_UNPRINTABLE}]"
        pattern = _PATTERNS[keep] = re.compile(body)
    shown = pattern.sub(_escaped_control, escape(text))
    if limit is not None and len(shown) > limit:
        shown = (
            f"{shown[:limit]}... [cut: {len(text):,} characters in all; the JSON report holds them]"
        )
    return shown


def _escaped_control(match: re.Match[str]) -> str:
    char = match.group()
    if char in _SHORT:
        return _SHORT[char]
    return f"\\x{ord(char):02x}" if ord(char) < 0x100 else f"\\u{ord(char):04x}"


def usd_path(path: str) -> str | bytes:
    """``path`` as USD's Python bindings accept it: a name that is not UTF-8
    goes as its bytes (the bindings cannot convert its surrogate escapes)."""
    return path if is_utf8(path) else os.fsencode(path)


def is_utf8(path: str) -> bool:
    """Whether ``path`` is UTF-8 (no surrogate escapes of bytes that are not)."""
    try:
        path.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


def single_root(path: str) -> str:
    """``path`` with a leading ``//`` written ``/``. Run from ``/``, OpenUSD
    makes a relative layer path absolute by joining it to the working
    directory with a slash (``Sdf.Layer.FindOrOpen("tmp/a.usda").realPath`` is
    ``//tmp/a.usda``); POSIX leaves such a name to the system, Linux and macOS
    read it as ``/``, and Python keeps it (``os.path.abspath``), so the
    layer would not be named as the file it is."""
    if path.startswith("//") and not path.startswith("///") and os.sep == "/":
        return path[1:]
    return path


def from_usd_text(text: str) -> str:
    """A path USD handed back as text, as Python names the file. The bindings
    decode a name's bytes as UTF-8; Python decodes them with the file system
    encoding, which under a POSIX locale without UTF-8 mode (``LC_ALL=C
    PYTHONUTF8=0``) is ASCII: there ``é`` is two surrogate escapes, and the
    bindings' ``é`` names no file (``os.stat`` raises UnicodeEncodeError)."""
    if _FS_ENCODING == "utf-8" or text.isascii():
        return text
    return os.fsdecode(text.encode("utf-8"))


_FS_ENCODING = sys.getfilesystemencoding().lower().replace("_", "-")


def from_usd(exc: UnicodeDecodeError) -> str | None:
    """The path USD handed back when its bytes are not UTF-8 (the bindings
    raise, holding the bytes in the error), as Python names such a file."""
    return os.fsdecode(exc.object) if isinstance(exc.object, bytes) else None


def _width(char: str) -> int:
    """The columns a terminal gives ``char`` (wcwidth's rule for printable text)."""
    if unicodedata.combining(char):
        return 0
    return 2 if unicodedata.east_asian_width(char) in ("W", "F") else 1


def columns(text: str) -> int:
    """The columns ``text`` takes on a terminal."""
    return sum(_width(char) for char in text)


def fitting(text: str, room: int) -> str:
    """The longest start of ``text`` that takes at most ``room`` columns."""
    used = 0
    for index, char in enumerate(text):
        used += _width(char)
        if used > room:
            return text[:index]
    return text
