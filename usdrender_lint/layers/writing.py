"""Writing fixed layers safely.

A layer is replaced atomically (a temporary file in its folder, then a rename),
so an interrupted write leaves the original intact. Before the rename the file
must still hold the bytes read when fixing started: an edit made meanwhile is
never lost (the file is left alone and the run exits 2). The new file keeps the
old one's mode, owner and group (as far as the user may set them), and a file
with several hard links is not replaced at all: a rename would split the links.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable
from pathlib import Path

from pxr import Sdf, Tf

from ..atomic import replace_atomically
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
    # A file without write permission is read-only even to root, who may write it anyway.
    if not os.access(path, os.W_OK) or not stat.st_mode & 0o222:
        return f"{shown} is read-only"
    if stat.st_nlink > 1:
        return (
            f"{shown} has {stat.st_nlink} hard links, which replacing it would split; "
            "--fix leaves it alone (use --fix-to LAYER, or fix one copy)"
        )
    folder = os.path.dirname(os.path.realpath(path)) or "."
    if not os.access(folder, os.W_OK | os.X_OK):
        return f"the folder of {shown} is read-only (the safe write needs it)"
    return None


def replace_file(state: DiskState, write: Callable[[Path], None]) -> None:
    """Replace the file read as ``state`` by what ``write`` puts into a temporary
    file, if it has not changed since. Raises ChangedOnDisk or OSError; the
    original is intact on any failure."""
    state.check_unchanged()
    stat = os.stat(state.path)

    def write_keeping_owner(temporary: Path) -> None:
        write(temporary)
        keep_owner(temporary, stat.st_uid, stat.st_gid)

    destination = Path(state.path)
    replace_atomically(destination, write_keeping_owner, destination.suffix)


def keep_owner(path: Path, uid: int, gid: int) -> None:
    """Give ``path`` this owner and group, or at least the group, as permitted."""
    now = os.stat(path)
    if (now.st_uid, now.st_gid) == (uid, gid):
        return
    try:
        os.chown(path, uid, gid)
    except PermissionError:
        with contextlib.suppress(PermissionError):
            os.chown(path, -1, gid)


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
    own encoding (a binary .usd stays binary)."""
    args = {"format": "usdc"} if Path(state.path).suffix.lower() == ".usd" else {}
    replace_file(state, lambda temporary: export(layer, str(temporary), args))


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
