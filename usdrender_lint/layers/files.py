"""A layer's file as Python names it, and whether a file can be handed to USD
at all: the floor both the engine (reading) and the fixer (writing) stand on."""

from __future__ import annotations

import errno
import os
import stat

from pxr import Ar, Sdf

from ..api.files import lfs_pointer_problem
from ..paths import from_usd, from_usd_text, single_root


def layer_real_path(layer: Sdf.Layer) -> str:
    """``layer.realPath`` as Python names the file: one that is not UTF-8 too
    (the bindings' strict decoding raises on it), and any under a locale whose
    file system encoding is not UTF-8 (:func:`~usdrender_lint.paths.from_usd_text`)."""
    try:
        return single_root(from_usd_text(layer.realPath))
    except UnicodeDecodeError as exc:
        return single_root(_undecoded(exc))


def layer_identifier(layer: Sdf.Layer) -> str:
    """``layer.identifier``, as :func:`layer_real_path` reads a path."""
    try:
        return from_usd_text(layer.identifier)
    except UnicodeDecodeError as exc:
        return _undecoded(exc)


def resolver_context_key(context: Ar.ResolverContext) -> str:
    """What the result cache keys a resolver context by: its repr, or, when a
    path in it is not UTF-8, its debug string as Python names such bytes (the
    repr's conversion would print an error on stderr and name the path None)."""
    try:
        context.GetDebugString()
    except UnicodeDecodeError as exc:
        return f"Ar.ResolverContext debug string: {_undecoded(exc)}"
    return repr(context)


def _undecoded(exc: UnicodeDecodeError) -> str:
    path = from_usd(exc)
    if path is None:
        raise exc
    return path


def real_path(layer: Sdf.Layer) -> str:
    """The layer's file (its identifier when it has none); a file name that is
    not UTF-8 as Python names such a file."""
    return layer_real_path(layer) or layer_identifier(layer)


#: Why a FIFO or a device is never handed to USD: opening it can block forever
#: (a named pipe's open waits for a writer).
NOT_REGULAR = "not a regular file"


def unreadable_reason(path: str) -> str | None:
    """Why ``path`` cannot be handed to USD at all, or None when it can. The
    file is really opened (not ``os.access``, which a privileged user passes):
    an unreadable file, or one in a folder without search permission, is
    "permission denied", never "no such file"."""
    try:
        mode = os.stat(path).st_mode
    except OSError as exc:
        if exc.errno in (errno.ENOENT, errno.ELOOP) and os.path.islink(path):
            return "a broken or looping symbolic link"
        return _os_reason(exc)
    if stat.S_ISDIR(mode):
        # Discovery hands over a folder only when it could not list it.
        try:
            os.listdir(path)
        except OSError as exc:
            return _os_reason(exc)
        return "is a directory"
    if not stat.S_ISREG(mode):
        return NOT_REGULAR
    try:
        os.close(os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0)))
    except OSError as exc:
        return _os_reason(exc)
    return None


def _os_reason(exc: OSError) -> str:
    if exc.errno == errno.ENOENT:
        return "no such file"
    if exc.errno in (errno.EACCES, errno.EPERM):
        return "permission denied"
    return (exc.strerror or str(exc)).lower()


__all__ = [
    "layer_identifier",
    "layer_real_path",
    "lfs_pointer_problem",
    "real_path",
    "unreadable_reason",
]
