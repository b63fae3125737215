"""Atomic file writes: a reader sees the old file or the new one, never half."""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Callable
from pathlib import Path


def write_text_atomic(path: str | Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file in the same folder
    and ``os.replace`` (atomic on POSIX and Windows). Raises OSError."""

    def write(temporary: Path) -> None:
        with open(temporary, "w", encoding="utf-8", newline="\n") as stream:
            stream.write(text)
            stream.flush()
            os.fsync(stream.fileno())

    replace_atomically(path, write)


def write_output(path: str | Path, text: str) -> None:
    """Write a file the user named for output (``--output``, ``--write-baseline``)
    as a shell's ``>`` would, but atomically where that is possible: a regular
    file (or a new one) is replaced atomically; a symbolic link is followed and
    its target replaced, the link kept; a FIFO or a device is opened and
    written in place (a stream cannot be replaced, and replacing it would
    put a regular file where the device was). Raises OSError."""
    target = os.path.realpath(path)
    try:
        mode = os.stat(target).st_mode
    except FileNotFoundError:
        mode = None
    if mode is not None and stat.S_ISDIR(mode):
        raise IsADirectoryError(21, os.strerror(21), str(path))
    if mode is not None and not stat.S_ISREG(mode):
        with open(target, "w", encoding="utf-8", newline="\n") as stream:
            stream.write(text)
        return
    write_text_atomic(target, text)


def replace_atomically(
    path: str | Path, write: Callable[[Path], None], suffix: str = ".tmp"
) -> None:
    """Replace ``path`` by what ``write`` puts into a temporary file (named with
    ``suffix``) in the same folder, keeping the replaced file's permissions.
    On any failure the original is intact and the temporary file is removed."""
    target = Path(path)
    handle, temporary = tempfile.mkstemp(
        prefix=f".{target.name}.", suffix=suffix, dir=target.parent
    )
    os.close(handle)
    try:
        write(Path(temporary))
        if target.exists():
            os.chmod(temporary, target.stat().st_mode & 0o7777)
        else:
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(temporary, 0o666 & ~umask)
        os.replace(temporary, target)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
