"""``--diff`` output: a patch that ``patch -p0`` and ``git apply -p0`` accept.

One unified diff per changed text layer, as ruff writes them: both headers
name the file as the user would (``--- shots/shot.usda`` / ``+++
shots/shot.usda``), relative to the current directory when it is below it,
else as the command line gave it (``../other/shot.usda``, an absolute path),
with ``\\ No newline at end of file`` after a last line without one. Neither
tool applies a name outside the current directory by itself (GNU patch calls
it dangerous, git an unsafe path): ``patch -p0 FILE`` and ``git apply -p0
--unsafe-paths`` do.
"""

from __future__ import annotations

import difflib
import os

from ..paths import printable

NO_NEWLINE = "\\ No newline at end of file\n"


def patch_name(path: str, cwd: str | None = None, given: str | None = None) -> str:
    """``path`` relative to the current directory with ``/`` separators when it
    is below it; else ``given`` (the name the command line gave the file)
    when that names it, else its absolute path."""
    cwd = os.path.realpath(cwd or os.getcwd())
    real = os.path.realpath(path)
    try:
        relative = os.path.relpath(real, cwd)
    except ValueError:  # another drive (Windows)
        relative = None
    if relative is not None and not (
        relative == os.pardir or relative.startswith(os.pardir + os.sep)
    ):
        return relative.replace(os.sep, "/")
    if given and os.path.realpath(os.path.join(cwd, given)) == real:
        return os.path.normpath(given).replace(os.sep, "/")
    return real.replace(os.sep, "/")


def patch(path: str, old: str, new: str, cwd: str | None = None, given: str | None = None) -> str:
    """The unified diff from ``old`` to ``new`` for the file at ``path`` (empty
    when nothing changed); ``given``: the file's name on the command line."""
    name = header_name(patch_name(path, cwd, given))
    out = []
    lines = difflib.unified_diff(_lines(old), _lines(new), fromfile=name, tofile=name)
    for line in lines:
        out.append(line)
        if not line.endswith("\n"):
            out.append("\n" + NO_NEWLINE)
    return "".join(out)


def merged(original: str, versions: list[str]) -> str | None:
    """One text holding the edits each of ``versions`` made to ``original``
    (an edit several made, once): what --fix leaves when the stages that share
    a layer fix it one after another. None when two versions change the same
    line differently, which no single patch can say."""
    base = original.splitlines(keepends=True)
    changed: dict[int, str | None] = {}  # a line of base: its new text, None deleted
    added: dict[int, list[str]] = {}  # lines added before a line of base (or at the end)
    for version in dict.fromkeys(versions):
        lines = version.splitlines(keepends=True)
        matcher = difflib.SequenceMatcher(None, base, lines, autojunk=False)
        for tag, i1, i2, j1, j2 in matcher.get_opcodes():
            if tag == "equal":
                continue
            # Line for line, then what is left over: lines added or deleted.
            pairs = min(i2 - i1, j2 - j1)
            news: list[str | None] = [*lines[j1 : j1 + pairs], *[None] * (i2 - i1 - pairs)]
            for index, new in enumerate(news, i1):
                if changed.setdefault(index, new) != new:
                    return None
            extra = lines[j1 + pairs : j2]
            if extra:
                have = added.setdefault(i2, [])
                added[i2] = _union(have, extra)
    out: list[str] = []
    for index, line in enumerate(base):
        out += added.get(index, [])
        new = changed.get(index, line)
        if new is not None:
            out.append(new)
    return "".join(out + added.get(len(base), []))


def _union(have: list[str], extra: list[str]) -> list[str]:
    """Lines two versions add at one place: the longer when one starts with the
    other, else both."""
    if have[: len(extra)] == extra:
        return have
    if extra[: len(have)] == have:
        return extra
    return have + extra


#: The C escapes git writes in a quoted file name (and git apply and GNU patch read).
_C_ESCAPES = {7: "\\a", 8: "\\b", 9: "\\t", 10: "\\n", 11: "\\v", 12: "\\f", 13: "\\r"}


def header_name(name: str) -> str:
    """``name`` as a patch header carries it: as it is, or, when it holds a
    control character (paths.printable), a quote, a backslash or bytes that
    are not UTF-8 (which would break the header or forge lines), or a space
    (GNU patch ends an unquoted name there), quoted as git quotes it:
    ``"a/x\\ny"``, other bytes than ASCII as octal escapes."""
    raw = os.fsencode(name)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        text = None
    if text is not None and printable(text, limit=None) == text and not set('"\\ ') & set(text):
        return name
    out = []
    for byte in raw:
        if byte in _C_ESCAPES:
            out.append(_C_ESCAPES[byte])
        elif byte in b'"\\':
            out.append("\\" + chr(byte))
        elif byte < 0x20 or byte >= 0x7F:
            out.append(f"\\{byte:03o}")
        else:
            out.append(chr(byte))
    return '"' + "".join(out) + '"'


def _lines(text: str) -> list[str]:
    """Lines as the patch tools count them: split at ``\\n`` only (``splitlines``
    would also split at form feeds and Unicode line separators)."""
    parts = text.split("\n")
    lines = [part + "\n" for part in parts[:-1]]
    if parts[-1]:
        lines.append(parts[-1])
    return lines
