"""Which files a run lints: the paths given, folders expanded recursively into
USD files (sorted), each file once. A folder that cannot be listed is kept in
the list in place of its files, so the engine reports it (``permission
denied``) instead of the run skipping it.

Walking a folder skips, as ruff does: hidden files and folders (``.git``,
``.venv``), what the ``exclude`` and ``extend-exclude`` settings name
(gitignore-style patterns, relative to the configuration's folder), and what
``.gitignore`` files ignore (those of the folders walked and of their parents
up to the repository's root, and ``.git/info/exclude``). A path given on the
command line is linted whatever its name, unless ``force-exclude`` is set (as
ruff's ``--force-exclude``): then a path given below the configuration's folder
is skipped where a walk from that folder would skip it, so a pre-commit hook,
which names every staged file, lints what ``check .`` lints.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

from ..engine import USD_EXTENSIONS
from ..paths import tidy
from ..records import record
from .globs import expand_all

if TYPE_CHECKING:
    from pathspec import PathSpec

    from ..config import Settings


@record(frozen=True)
class Exclusions:
    """What a folder walk skips."""

    patterns: tuple[str, ...] = ()
    #: The folder ``patterns`` are relative to.
    base: str = "."
    respect_gitignore: bool = True
    skip_hidden: bool = True
    #: Skip a path given too where a walk from ``base`` would (force-exclude).
    force: bool = False

    @classmethod
    def of(cls, settings: Settings) -> Exclusions:
        return cls(
            tuple(settings.exclude) + tuple(settings.extend_exclude),
            str(settings.base_dir),
            settings.respect_gitignore,
            force=settings.force_exclude,
        )


#: Nothing skipped: every USD file below a folder (the Python API's default).
EVERYTHING = Exclusions(skip_hidden=False, respect_gitignore=False)


#: The exclusions of the configuration a folder keeps (None: it keeps none, and its
#: parent's hold in it).
FolderExclusions = Callable[[str], "Exclusions | None"]


def collect_files(
    paths: Iterable[str],
    empty: list[str] | None = None,
    exclusions: Exclusions = EVERYTHING,
    nested: FolderExclusions | None = None,
) -> list[str]:
    """Expand directories recursively into USD files (sorted); keep files,
    missing paths and folders that cannot be listed as given so the engine
    reports them. The folders that hold no USD file are added to ``empty``.
    With ``exclusions.force``, a path given that a walk would skip is left out.
    ``nested``: below a folder with a configuration of its own, that one's
    exclusions judge what the walk meets, as ruff walks (the folder itself is
    judged by its parent's)."""
    files: list[str] = []
    given = _Given(exclusions, nested) if exclusions.force else None
    for path in paths:
        if given is not None and given.skipped(path):
            continue
        if os.path.isdir(path):
            found = _walk(path, exclusions, nested)
            if not found and empty is not None:
                empty.append(path)
            files.extend(found)
        else:
            files.append(path)
    seen: set[str] = set()
    unique = []
    for f in files:
        key = _same_file_key(f)
        if key not in seen:
            seen.add(key)
            # Every report names the file so (text, JSON, SARIF...): `check .` gives x.usda.
            unique.append(tidy(f))
    return unique


def _same_file_key(path: str) -> str:
    """One key for the names of one path: relative or absolute, ``./`` or not (a
    file named both ways was linted and reported twice). Symbolic links are not
    followed: a link is linted as the user named it."""
    try:
        return os.path.abspath(path)
    except OSError:  # the working directory is gone, or too long to name
        return os.path.normpath(path)


def _walk(top: str, exclusions: Exclusions, nested: FolderExclusions | None) -> list[str]:
    found: list[str] = []
    #: What judges the entries of each folder still to be walked: at the top, the
    #: nearest configuration at or above it.
    skips = {top: _Skip(top, _nearest(top, nested) or exclusions)}

    def unlisted(error: OSError) -> None:
        found.append(error.filename if isinstance(error.filename, str) else top)

    for folder, dirs, names in os.walk(top, onerror=unlisted, followlinks=False):
        skip = skips.pop(folder)
        own = nested(folder) if nested is not None else None
        if own is not None and own != skip.exclusions:
            skip = _Skip(folder, own)
        skip.enter(folder)
        dirs[:] = sorted(d for d in dirs if not skip(os.path.join(folder, d), d, folder=True))
        skips.update((os.path.join(folder, d), skip) for d in dirs)
        found.extend(
            os.path.join(folder, n)
            for n in names
            if n.lower().endswith(USD_EXTENSIONS) and not skip(os.path.join(folder, n), n)
        )
    return sorted(found)


def _nearest(top: str, nested: FolderExclusions | None) -> Exclusions | None:
    """The exclusions of the nearest folder at or above ``top`` that keeps a
    configuration (None: none does, or the run has one configuration)."""
    if nested is None:
        return None
    folder = os.path.abspath(top)
    while (own := nested(folder)) is None:
        parent = os.path.dirname(folder)
        if parent == folder:
            return None
        folder = parent
    return own


def repository_chain(top: str) -> tuple[list[str], str | None]:
    """The folders whose ``.gitignore`` a walk of ``top`` reads from above it:
    ``top`` and its parents up to its repository's root, and that root; outside
    a repository, ``top`` alone and None."""
    chain = []
    folder = top
    while True:
        chain.append(folder)
        if os.path.exists(os.path.join(folder, ".git")):
            return chain, folder
        parent = os.path.dirname(folder)
        if parent == folder:
            return [top], None  # only the walked folders' own
        folder = parent


def git_exclude(root: str) -> str:
    """git's own ignore file of the repository at ``root``."""
    return os.path.join(root, ".git", "info", "exclude")


class _Skip:
    """Whether a path met in a walk is skipped (see the module docstring)."""

    def __init__(self, top: str, exclusions: Exclusions) -> None:
        self.exclusions = exclusions
        # Braces as the other keys' globs read them (running/globs.py); a
        # .gitignore's lines are git's, which has none.
        patterns = expand_all(exclusions.patterns)
        self.excluded = _spec(patterns) if patterns else None
        self.base = os.path.abspath(exclusions.base)
        #: (folder, spec) of every .gitignore in force, outermost first.
        self.ignores: list[tuple[str, PathSpec | _Names]] = []
        self.read: set[str] = set()
        self.enter_chain(top)

    def enter_chain(self, top: str) -> None:
        """The .gitignore files of ``top`` and above it up to its repository's root."""
        if self.exclusions.respect_gitignore:
            self._parents_of(os.path.abspath(top))

    def _parents_of(self, top: str) -> None:
        chain, root = repository_chain(top)
        if root is not None:
            self._add(root, git_exclude(root))
        for folder in reversed(chain):
            self.enter(folder)

    def enter(self, folder: str) -> None:
        if self.exclusions.respect_gitignore:
            real = os.path.abspath(folder)
            self._add(real, os.path.join(real, ".gitignore"))

    def _add(self, folder: str, path: str) -> None:
        if path in self.read:
            return
        self.read.add(path)
        try:
            with open(path, encoding="utf-8", errors="replace") as handle:
                lines = handle.read(1 << 20).splitlines()
        except OSError:
            return
        self.ignores.append((folder, _spec(lines)))
        # Outermost first, whatever order the folders were met in (a deeper file wins).
        self.ignores.sort(key=lambda item: item[0].count(os.sep))

    def __call__(self, path: str, name: str, folder: bool = False) -> bool:
        if self.exclusions.skip_hidden and name.startswith("."):
            return True
        real = os.path.abspath(path)
        suffix = "/" if folder else ""
        if self.excluded is not None:
            relative = _below(real, self.base)
            if relative is not None and self.excluded.match_file(relative + suffix):
                return True
            if relative is None and self.excluded.match_file(name + suffix):
                return True
        ignored = False
        for base, spec in self.ignores:
            relative = _below(real, base)
            if relative is None:
                continue
            result = spec.check_file(relative + suffix)
            if result.include is not None:
                ignored = bool(result.include)
        return ignored


def force_excluded(
    path: str, exclusions: Exclusions, nested: FolderExclusions | None = None
) -> bool:
    """Whether ``path``, given by name, is left out under ``exclusions.force``
    (``check -``'s ``--stdin-filename``, an editor's document)."""
    return exclusions.force and _Given(exclusions, nested).skipped(path)


def walk_skips(
    exclusions: Exclusions, nested: FolderExclusions | None = None
) -> Callable[[str], bool]:
    """Whether a walk would skip a path (see :class:`_Given`): one test for many
    paths, each .gitignore read once."""
    return _Given(exclusions, nested).skipped


class _Given:
    """Whether a path given is skipped where a walk would skip it (force-exclude):
    a walk from the outermost folder above it that keeps a configuration, each
    folder's own configuration judging what is in it (``nested``, as ruff judges
    a path's ancestors), so the answer does not depend on which path came first;
    without ``nested`` (one configuration for the run), a walk from the
    configuration's folder. One walk's state serves every path (each .gitignore
    applies only below its own folder), so a pre-commit hook's thousand staged
    files read each .gitignore once."""

    def __init__(self, exclusions: Exclusions, nested: FolderExclusions | None = None) -> None:
        self.base = os.path.abspath(exclusions.base)
        self.exclusions = exclusions
        self.nested = nested
        self._skips: dict[str, _Skip] = {}
        #: The outermost folder at or above each folder asked about that keeps a configuration.
        self._outermost: dict[str, str | None] = {}

    def skipped(self, path: str) -> bool:
        real = os.path.abspath(path)
        top = self._outermost_above(os.path.dirname(real)) or self.base
        relative = _below(real, top)
        if relative is None:  # the configuration's folder or outside it: not for its patterns
            return False
        folder = top
        skip = self._skip_in(folder)
        skip.enter(folder)
        parts = relative.split("/")
        for part in parts[:-1]:
            folder = os.path.join(folder, part)
            if skip(folder, part, folder=True):
                return True
            if self.nested is not None and self.nested(folder) is not None:
                skip = self._skip_in(folder)  # the folder's own configuration judges in it
            skip.enter(folder)  # as the walk reads each folder's .gitignore it goes into
        return skip(real, parts[-1], folder=os.path.isdir(real))

    def _skip_in(self, folder: str) -> _Skip:
        """What judges the entries of ``folder`` (a configured folder, or the top)."""
        if folder not in self._skips:
            own = self.nested(folder) if self.nested is not None else None
            self._skips[folder] = _Skip(folder, own or self.exclusions)
        return self._skips[folder]

    def _outermost_above(self, folder: str) -> str | None:
        if self.nested is None:
            return None
        if folder not in self._outermost:
            parent = os.path.dirname(folder)
            above = None if parent == folder else self._outermost_above(parent)
            mine = folder if self.nested(folder) is not None else None
            self._outermost[folder] = above or mine
        return self._outermost[folder]


def _below(path: str, folder: str) -> str | None:
    """``path`` relative to ``folder`` with ``/`` separators, None when not below it."""
    relative = os.path.relpath(path, folder)
    if relative == os.curdir or relative.startswith(os.pardir):
        return None
    return Path(relative).as_posix()


def _spec(lines: Iterable[str]) -> PathSpec | _Names:
    """A gitignore matcher of ``lines`` (``match_file``, ``check_file``)."""
    lines = list(lines)
    names = _plain_names(lines)
    if names is not None:
        return _Names(names)
    from pathspec import GitIgnoreSpec  # only for a walk that skips by pattern

    try:
        return GitIgnoreSpec.from_lines(lines)
    except ValueError:
        # A line pathspec refuses (a lone '!', a trailing backslash) matches
        # nothing for git, which reads the other lines: so here.
        return GitIgnoreSpec.from_lines([line for line in lines if _readable(line)])


def _readable(line: str) -> bool:
    from pathspec import GitIgnoreSpec

    try:
        GitIgnoreSpec.from_lines([line])
    except ValueError:
        return False
    return True


#: What makes a gitignore line more than a file or folder name.
_PATTERN_CHARS = frozenset("*?[]\\/!")


def _plain_names(lines: list[str]) -> frozenset[str] | None:
    """The names ``lines`` list when each is a blank line, a comment or a bare
    name (the default ``exclude``, git's own ``info/exclude``), else None."""
    names = set()
    for line in lines:
        if not line or line.startswith("#"):
            continue
        if line != line.strip() or not _PATTERN_CHARS.isdisjoint(line) or not line.strip("."):
            return None
        names.add(line)
    return frozenset(names)


class _Check(NamedTuple):
    #: As pathspec's CheckResult: True when a pattern ignores the path, None when none matches.
    include: bool | None


class _Names:
    """Gitignore's reading of bare names, without importing pathspec (about 10
    ms of a folder walk's start-up): a name with no slash matches a file or
    folder of that name at any depth, and with it everything below."""

    def __init__(self, names: frozenset[str]) -> None:
        self.names = names

    def match_file(self, path: str) -> bool:
        return not self.names.isdisjoint(path.split("/"))

    def check_file(self, path: str) -> _Check:
        return _Check(True if self.match_file(path) else None)
