"""Writing fixed layers safely.

A layer is replaced atomically (a temporary file in its folder, then a rename),
so an interrupted write leaves the original intact. Before and after the
temporary file is written, and after the rename, the file must still hold the
bytes read when fixing started: an edit made meanwhile is never lost (the file
is left alone, or put back, and the run exits 2). The new file keeps the old
one's mode, owner and group; a file whose owner or group a new file cannot
have (another user's) is left alone with a message, and a file with several
hard links is not replaced at all: a rename would split the links.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable
from pathlib import Path

from pxr import Sdf, Tf

from ..atomic import is_read_only, keep_owner, replace_atomically, temporary_prefix
from ..layers.files import layer_identifier, layer_real_path
from ..paths import display_path, usd_path
from ..records import record

CRATE_MAGIC = b"PXR-USDC"


class ChangedOnDisk(OSError):
    """The file changed on disk after it was read for fixing."""


@record(frozen=True)
class DiskState:
    """A file as fixing read it: its real path, its bytes and its identity."""

    path: str
    data: bytes
    device: int
    inode: int

    @classmethod
    def read(cls, path: str) -> DiskState:
        """Raises OSError."""
        real = os.path.realpath(path)
        with open(real, "rb") as handle:
            stat = os.fstat(handle.fileno())
            data = handle.read()
        return cls(real, data, stat.st_dev, stat.st_ino)

    @property
    def is_crate(self) -> bool:
        return self.data.startswith(CRATE_MAGIC)

    def check_unchanged(self) -> None:
        """Raise ChangedOnDisk unless the file still is what was read."""
        try:
            now = DiskState.read(self.path)
        except OSError as exc:
            raise ChangedOnDisk(f"it can no longer be read: {exc.strerror or exc}") from None
        if (now.device, now.inode) != (self.device, self.inode) or now.data != self.data:
            raise ChangedOnDisk("it changed on disk while fixing; it was left as it is")


def write_problem(layer: Sdf.Layer, writing: bool = True) -> str | None:
    """Why --fix may not write ``layer``, or None when it may. With ``writing``
    False (--diff, which writes nothing) only why it cannot be read as a file."""
    path = layer_real_path(layer)
    if layer.anonymous or not path:
        return f"{layer.GetDisplayName()} is not a file on disk"
    shown = display_path(path)
    if layer.GetFileFormat().IsPackage() or layer_identifier(layer).endswith("]"):
        return (
            f"{shown} is inside a .usdz package, which --fix does not rewrite; "
            "use --fix-to LAYER to write the fixes as overrides"
        )
    try:
        stat = os.stat(path)
    except OSError as exc:
        return f"{shown} cannot be read: {exc.strerror or exc}"
    if not writing:
        return None
    if is_read_only(path, stat):
        return f"{shown} is read-only"
    if stat.st_nlink > 1:
        stale = _stale_backup(path, stat)
        if stale is not None:
            return (
                f"{shown} has a second name, {display_path(stale)}, the backup of a fix that "
                "was killed while it wrote; remove that file and fix again"
            )
        return (
            f"{shown} has {stat.st_nlink} hard links, which replacing it would split; "
            "--fix leaves it alone (use --fix-to LAYER, or fix one copy)"
        )
    folder = os.path.dirname(os.path.realpath(path)) or "."
    if not os.access(folder, os.W_OK | os.X_OK):
        return f"the folder of {shown} is read-only (the safe write needs it)"
    return None


def _stale_backup(path: str, stat: os.stat_result) -> str | None:
    """The backup hard link (:class:`_Held`) a write that never finished left
    beside ``path``, or None."""
    folder, name = os.path.split(os.path.realpath(path))
    prefix = temporary_prefix(name, ".orig")
    with contextlib.suppress(OSError):
        for entry in os.scandir(folder or "."):
            if entry.name.startswith(prefix) and entry.name.endswith(".orig"):
                found = entry.stat(follow_symlinks=False)
                if (found.st_dev, found.st_ino) == (stat.st_dev, stat.st_ino):
                    return entry.path
    return None


def replace_file(state: DiskState, write: Callable[[Path], None]) -> None:
    """Replace the file read as ``state`` by what ``write`` puts into a temporary
    file, if it has not changed since. Raises ChangedOnDisk or OSError; the
    original is intact on any failure.

    The file is compared with what was read before the temporary file is
    written, after it is written, and after the rename: an edit made in that
    window through the old file (a writer that opened it before the rename)
    would otherwise be lost with it, so the rename is undone (the old file,
    kept under a hard link meanwhile, is put back) and ChangedOnDisk raised."""
    state.check_unchanged()
    before = os.stat(state.path)
    destination = Path(state.path)

    def write_checked(temporary: Path) -> None:
        write(temporary)
        if not keep_owner(temporary, before.st_uid, before.st_gid):
            raise OSError(
                f"a new file cannot keep its owner and group ({before.st_uid}:{before.st_gid}) "
                "here; it was left as it is (fix it as its owner, or use --fix-to)"
            )
        state.check_unchanged()

    with _Held(state) as held:
        replace_atomically(destination, write_checked, destination.suffix)
        held.confirm()


class _Held:
    """The file being replaced, held through the rename: a hard link to it
    (to put it back) where the file system has them, and an open descriptor."""

    def __init__(self, state: DiskState) -> None:
        self.state = state
        self.fd = -1
        self.backup: str | None = None

    def __enter__(self) -> _Held:
        self.fd = os.open(self.state.path, os.O_RDONLY | getattr(os, "O_CLOEXEC", 0))
        folder, name = os.path.split(self.state.path)
        unique = os.urandom(4).hex()
        backup = os.path.join(folder, f"{temporary_prefix(name, '.orig')}{unique}.orig")
        try:
            os.link(self.state.path, backup)
            self.backup = backup
        except OSError:
            self.backup = None
        return self

    def confirm(self) -> None:
        """After the rename: raise ChangedOnDisk, with the old file back in
        place, when it changed since it was read."""
        data = _read_all(self.fd)
        if data == self.state.data:
            return
        if self.backup is not None:
            os.replace(self.backup, self.state.path)
            self.backup = None
        else:  # no hard links here: its content goes back, in a new file

            def put_back(temporary: Path) -> None:
                temporary.write_bytes(data)

            replace_atomically(self.state.path, put_back)
        raise ChangedOnDisk(
            "it changed on disk while the fix was written; the fix was undone and the "
            "other edit kept"
        )

    def __exit__(self, *exc_info: object) -> None:
        if self.backup is not None:
            with contextlib.suppress(OSError):
                os.unlink(self.backup)
        os.close(self.fd)


def _read_all(fd: int) -> bytes:
    chunks, offset = [], 0
    while chunk := os.pread(fd, 1 << 20, offset):
        chunks.append(chunk)
        offset += len(chunk)
    return b"".join(chunks)


def save_text(state: DiskState, text: str) -> None:
    """Write a text layer's new text over the file read as ``state``."""
    data = text.encode("utf-8")

    def write(temporary: Path) -> None:
        with open(temporary, "wb") as stream:
            stream.write(data)
            stream.flush()
            os.fsync(stream.fileno())

    replace_file(state, write)


def save_layer(layer: Sdf.Layer, state: DiskState) -> None:
    """Write ``layer`` over the file read as ``state`` through Sdf, in the file's
    own encoding (a binary .usd stays binary) and, for a crate, its version."""
    if state.is_crate:
        replace_file(state, lambda temporary: save_crate(layer, state.data, temporary))
        return
    args = {"format": "usdc"} if Path(state.path).suffix.lower() == ".usd" else {}
    replace_file(state, lambda temporary: export(layer, str(temporary), args))


def save_crate(layer: Sdf.Layer, original: bytes, path: Path) -> None:
    """Write ``layer`` to ``path`` as a crate of the version ``original`` (the
    file's bytes as read) has. Sdf writes a new crate file at the version
    USD_WRITE_NEW_USDC_FILES_AS_VERSION says (0.8.0 by default, read once per
    process), and keeps an existing file's version when it saves edits to it
    (OpenUSD pxr/usd/sdf/crateFile.cpp, that setting's description): so the
    original goes to ``path`` first, and ``layer``'s content is saved into it. A
    fix that needs a newer version (a value type the old one lacks) still gets
    it: Sdf upgrades the file as it saves."""
    path.write_bytes(original)
    try:
        with Tf.DiagnosticTrap() as trap:
            copy = Sdf.Layer.FindOrOpen(usd_path(str(path)))
            ok = copy is not None and Sdf.CopySpec(
                layer, Sdf.Path.absoluteRootPath, copy, Sdf.Path.absoluteRootPath
            )
            # What Sdf would write must be the layer, or the file gets an export.
            ok = ok and copy.ExportToString() == layer.ExportToString() and copy.Save()
            trap.Clear()
    except Tf.ErrorException:
        ok = False
    if not ok:
        export(layer, str(path), {"format": "usdc"})


def save_new_layer(layer: Sdf.Layer, path: str) -> None:
    """Write ``layer`` to a file that does not exist yet (atomically)."""
    destination = Path(path)
    replace_atomically(destination, lambda t: export(layer, str(t), {}), destination.suffix)


def export(layer: Sdf.Layer, path: str, args: dict[str, str]) -> None:
    """Sdf's export, with its errors as OSError (a test replaces this to fail)."""
    try:
        with Tf.DiagnosticTrap() as trap:
            ok = layer.Export(usd_path(path), args=args)
            trap.Clear()
    except Tf.ErrorException as exc:
        raise OSError(str(exc).strip().splitlines()[-1]) from None
    if not ok:
        raise OSError(f"USD could not write {path}")
