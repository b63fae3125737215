"""Writing the user's files: atomically where that can be (a reader sees the
old file or the new one, never half), streamed where it cannot (a pipe, a
FIFO, a terminal, the command's own stdout), always every byte."""

from __future__ import annotations

import contextlib
import errno
import os
import re
import select
import stat
import time
from collections.abc import Callable
from pathlib import Path

#: The longest file name most file systems take (NAME_MAX), in bytes.
NAME_MAX = 255
#: Names of a descriptor the process already holds: what a shell's
#: ``> /dev/stdout`` writes through (its offset and append mode), not a file
#: to open again and replace.
#: (Pattern text: re compiles it at first use, not at every start-up.)
_DESCRIPTOR_NAMES = r"/dev/fd/(\d+)|/proc/(?:self|thread-self|(\d+))/fd/(\d+)"
_STANDARD_NAMES = {"/dev/stdin": 0, "/dev/stdout": 1, "/dev/stderr": 2}
#: Seconds a named pipe the user names (a file made by ``mkfifo``) is given for its
#: other end: a reader to open it for an output, a writer to write into it for an
#: input (reading.py). Its plain open waits for that end without a limit.
PIPE_WAIT = 10.0
#: Seconds between tries to open a named pipe for writing while no reader has it.
_PIPE_RETRY = 0.05


def write_all(fd: int, data: bytes) -> None:
    """Write every byte of ``data`` to ``fd``. One ``write()`` may take only
    part (a pipe whose reader goes away takes what fits and says nothing), so
    this writes until all is out or the descriptor fails: a reader gone is a
    BrokenPipeError. A non-blocking descriptor is waited for."""
    view = memoryview(data)
    while view:
        try:
            written = os.write(fd, view)
        except BlockingIOError:
            select.select([], [fd], [])
            continue
        except InterruptedError:
            continue
        if written == 0:  # only ever for an empty write: never loop on it
            raise OSError(errno.EIO, os.strerror(errno.EIO))
        view = view[written:]


def named_descriptor(path: str | os.PathLike[str]) -> int | None:
    """The descriptor ``path`` names, when it is one this process holds
    (``/dev/stdout``, ``/dev/fd/3``, ``/proc/self/fd/1``, or a link to one),
    else None."""
    current = os.path.abspath(path)
    for _ in range(40):  # the kernel's own limit on links followed
        if current in _STANDARD_NAMES:
            return _STANDARD_NAMES[current]
        match = re.fullmatch(_DESCRIPTOR_NAMES, current)
        if match and match.group(2) in (None, str(os.getpid())):
            return int(match.group(1) or match.group(3))
        try:
            link = os.readlink(current)
        except OSError:
            return None
        current = os.path.normpath(os.path.join(os.path.dirname(current), link))
    return None


def write_text_atomic(path: str | Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file in the same folder
    and ``os.replace`` (atomic on POSIX and Windows). Raises OSError."""

    def write(temporary: Path) -> None:
        with open(temporary, "w", encoding="utf-8", newline="\n") as stream:
            stream.write(text)
            stream.flush()
            os.fsync(stream.fileno())

    replace_atomically(path, write)


def is_read_only(path: str | Path, stat_result: os.stat_result) -> bool:
    """Whether a file may not be written: a file without write permission is
    read-only even to root, who could write it anyway (--fix and the outputs
    leave it alone)."""
    return not os.access(path, os.W_OK) or not stat_result.st_mode & 0o222


def write_output(path: str | Path, text: str) -> None:
    """Write a file the user named for output (``--output``, ``--write-baseline``,
    ``spec --output``) as a shell's ``>`` would, but atomically where that is
    possible:

    - a descriptor this process holds (``/dev/stdout``, ``/dev/stderr``,
      ``/dev/fd/N``): written through it, at its offset and in its append
      mode, so ``{ echo A; check --output /dev/stdout; } >> log`` keeps A and
      what the log held;
    - a FIFO, a terminal or another device: opened and streamed into (a
      stream cannot be replaced, and replacing it would put a regular file
      where the device was); a named pipe once a reader has it, within
      PIPE_WAIT seconds (ETIMEDOUT past them);
    - a regular file (or a new one): replaced atomically, keeping its mode,
      owner and group; when its owner or group cannot be kept (another
      user's file in a shared folder) it is written in place instead, which
      keeps them; a symbolic link is followed and its target written, the
      link kept; a read-only file is left alone (PermissionError), as the
      shell's ``>`` leaves it;
    - a new file in folders that do not exist yet: they are created first, as
      ruff creates ``--output-file``'s (astral-sh/ruff#11550), so that
      ``--output reports/x.sarif`` does not lint everything and then fail.

    Raises OSError (BrokenPipeError: the reader went away)."""
    data = text.encode("utf-8")
    fd = named_descriptor(path)
    if fd is not None:
        write_all(fd, data)
        return
    target = os.path.realpath(path)
    try:
        before = os.stat(target)
    except FileNotFoundError:
        before = None
    if before is not None and stat.S_ISDIR(before.st_mode):
        raise IsADirectoryError(21, os.strerror(21), str(path))
    if before is not None and not stat.S_ISREG(before.st_mode):
        _write_in_place(target, data, truncate=False)
        return
    # The rename would replace a file the shell's > may not write.
    if before is not None and is_read_only(target, before):
        raise PermissionError(errno.EACCES, "the file is read-only", str(path))
    if before is None:
        os.makedirs(os.path.dirname(target), exist_ok=True)

    def write(temporary: Path) -> None:
        with open(temporary, "wb") as stream:
            stream.write(data)
            stream.flush()
            os.fsync(stream.fileno())
        if before is not None and not keep_owner(temporary, before.st_uid, before.st_gid):
            raise _OwnerNotKept

    try:
        replace_atomically(target, write)
    except _OwnerNotKept:
        _write_in_place(target, data, truncate=True)


class _OwnerNotKept(Exception):
    """The replacement could not be given the replaced file's owner or group."""


def _write_in_place(target: str, data: bytes, *, truncate: bool) -> None:
    flags = os.O_WRONLY | (os.O_TRUNC if truncate else 0) | getattr(os, "O_CLOEXEC", 0)
    fd = _open_named_pipe(target, flags) if is_named_pipe(target) else os.open(target, flags)
    try:
        write_all(fd, data)
    finally:
        os.close(fd)


def is_named_pipe(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` leads to a pipe made by ``mkfifo``, not to one the shell
    made: ``/dev/fd/63`` leads to ``pipe:[N]``, which names no file."""
    try:
        return stat.S_ISFIFO(os.stat(os.path.realpath(path)).st_mode)
    except OSError:
        return False


def _open_named_pipe(path: str, flags: int) -> int:
    """``os.open`` of a named pipe for writing, once a reader has it, within
    PIPE_WAIT seconds: a non-blocking open fails (ENXIO) while none has it,
    where a plain one would wait for a reader without end."""
    deadline = time.monotonic() + PIPE_WAIT
    while True:
        try:
            return os.open(path, flags | os.O_NONBLOCK)  # write_all waits on a full pipe
        except OSError as exc:
            if exc.errno != errno.ENXIO:
                raise
            if time.monotonic() >= deadline:
                raise OSError(
                    errno.ETIMEDOUT, f"a named pipe nothing read from within {PIPE_WAIT:g} s"
                ) from None
        time.sleep(_PIPE_RETRY)


def keep_owner(path: str | Path, uid: int, gid: int) -> bool:
    """Give ``path`` this owner and group, as far as permitted (at least the
    group); True when both are now the ones asked for."""
    now = os.stat(path)
    if (now.st_uid, now.st_gid) == (uid, gid):
        return True
    try:
        os.chown(path, uid, gid)
        return True
    except PermissionError:
        with contextlib.suppress(PermissionError):
            os.chown(path, -1, gid)
    return False


def replace_atomically(
    path: str | Path, write: Callable[[Path], None], suffix: str = ".tmp"
) -> None:
    """Replace ``path`` by what ``write`` puts into a temporary file (named with
    ``suffix``) in the same folder, keeping the replaced file's permissions.
    On any failure the original is intact and the temporary file is removed."""
    target = Path(path)
    import tempfile  # not at import: a lint that writes no file never needs it

    handle, temporary = tempfile.mkstemp(
        prefix=temporary_prefix(target.name, suffix), suffix=suffix, dir=target.parent
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


def temporary_prefix(name: str, suffix: str) -> str:
    """``.NAME.``, the prefix of a temporary file beside ``name``, short enough
    for the whole temporary name (prefix, 8 random characters, suffix) to stay
    within NAME_MAX bytes: a long name is cut and made unique by a hash of it."""
    prefix = f".{name}."
    room = NAME_MAX - len(os.fsencode(suffix)) - 8 - 1
    if len(os.fsencode(prefix)) <= room:
        return prefix
    # Imported only here: writing stdout (write_all) is every run's, and
    # hashlib's start-up (OpenSSL) is not.
    import hashlib

    digest = hashlib.sha256(os.fsencode(name)).hexdigest()[:12]
    cut = os.fsdecode(os.fsencode(name)[: room - len(digest) - 3])
    return f".{cut}~{digest}."
