"""What a rule may ask about a file on disk, beside what USD composed of it."""

from __future__ import annotations

#: How a Git LFS pointer file starts (https://github.com/git-lfs/git-lfs/blob/main/docs/spec.md:
#: "version https://git-lfs.github.com/spec/v1" is its first line).
LFS_POINTER_START = b"version https://git-lfs.github.com/spec/"
#: The spec's pointer files are under 1024 bytes.
_LFS_POINTER_MAX = 1024


def lfs_pointer_problem(path: str) -> str | None:
    """What to say when ``path`` is a Git LFS pointer (the checkout has the
    pointer text, not the layer: ``git lfs pull`` was not run), else None."""
    try:
        with open(path, "rb") as handle:
            head = handle.read(_LFS_POINTER_MAX + 1)
    except (OSError, ValueError):
        return None
    if not head.startswith(LFS_POINTER_START) or len(head) > _LFS_POINTER_MAX:
        return None
    return (
        "this is a Git LFS pointer, not the layer: the repository stores the file in Git "
        "LFS and this checkout holds only its pointer; fetch it with `git lfs pull`"
    )
