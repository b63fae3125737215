"""Reading a file the user names as an input of a run (a baseline, a report to
merge) without waiting forever on it (no pxr).

A plain ``open()`` of a named pipe waits for a writer, and a read of a device
such as ``/dev/zero`` never ends: the command hung without a word. A pipe is
still read to its writer's end, as ``cat`` reads it: one the shell hands over
(``merge <(cat shard.json)``, ``/dev/stdin``) has its writer already, and a named
pipe (a file made by ``mkfifo``) must be written to within ``atomic.PIPE_WAIT`` seconds.
Any other file that is not a regular one is refused.
"""

from __future__ import annotations

import errno
import os
import select
import stat

from . import atomic

#: Why any other file that is not a regular one is refused.
NOT_A_FILE = "not a regular file or a pipe"


def read_named_input(path: str | os.PathLike[str]) -> bytes:
    """The bytes of the regular file or pipe at ``path``. Raises OSError (its
    ``strerror`` says why in a few words) for a folder, a device or a socket,
    and for a named pipe nothing wrote to within ``atomic.PIPE_WAIT`` seconds."""
    # O_NONBLOCK: opening a named pipe returns at once instead of waiting for a writer.
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    try:
        mode = os.fstat(fd).st_mode
        if stat.S_ISDIR(mode):
            raise IsADirectoryError(errno.EISDIR, "Is a directory")
        if stat.S_ISFIFO(mode):
            # Readable once a writer wrote or closed; on Linux a pipe no writer has
            # opened yet is not (pipe_poll, fs/pipe.c), where a read would say it ended.
            wait = atomic.PIPE_WAIT
            if atomic.is_named_pipe(path) and not select.select([fd], [], [], wait)[0]:
                raise OSError(errno.ETIMEDOUT, f"a named pipe nothing wrote to within {wait:g} s")
            os.set_blocking(fd, True)  # then read to the writer's end
        elif not stat.S_ISREG(mode):
            raise OSError(errno.EINVAL, NOT_A_FILE)
        chunks = []
        while chunk := os.read(fd, 1 << 20):
            chunks.append(chunk)
        return b"".join(chunks)
    finally:
        os.close(fd)


__all__ = ["NOT_A_FILE", "read_named_input"]
