"""The result cache: a file's findings are reused while nothing they depend on
has changed (``check`` uses it by default, like ruff's; ``--no-cache`` turns it off).

An entry is found by the **run key** (the tool's version and code, usd-core's
version, the rules that run with their options, the severities, every setting
that can change a finding, the environment that configures USD or the linter)
and the file as given with the working directory. It holds the file's result
and what the result depends on (engine/assets.py ``Reads``), each checked on
lookup:

- the **content digest** of every file the lint read (the root layer first: an
  entry is only ever served for the file it names), its sublayers, the
  references and payloads it reached, the value clips, the layers the fast path
  scanned, and, as "absent", each asset an arc names that did not exist;
- the **real path** of each of those files as named (a retargeted symbolic
  link, the file's or a folder's, is another file);
- the **existence** of each asset a rule checked (``Context.depends_on_asset``);
- what the resolver finds for each **search path** an arc names, in the
  **resolver context** the stage is opened with (a file appearing earlier on
  ``PXR_AR_DEFAULT_SEARCH_PATH``, in the working directory or next to the
  layer naming it is found instead);
- the files each value clip **template** matches in its folder.

Results that are not known to be complete (a stage USD could not open, a file
the tool could not lint, a rule that raised (UL000), a layer with unsaved
edits, an asset path whose file depends on more than its path) are never
stored, nor is a result when a file it depends on changed after the lint
began: its digest is taken before the lint and compared after it, and every
dependency's change time (which a copy keeping times, ``cp -p``, cannot set
back) must predate the lint, as must the folders on the way to them (a folder
renamed into place keeps its files' times).

The folder is the cache's own: created by it (with a ``CACHEDIR.TAG`` and a
``.gitignore``), or empty when first used (it gets the tag only), or holding
its tag; any other folder is refused (:class:`ForeignFolder`). Entries are one
JSON file each, written atomically, so concurrent runs (CI shards sharing a
cache) never see half an entry; an entry is read only when it is a regular
file of bounded size (a FIFO, a link, a folder or a deeply nested document is
ignored, and replaced on the next store). After a run that linted files, the
least recently used entry files (by name) are removed beyond MAX_BYTES.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import json
import os
import re
import shutil
import stat
import sys
import tempfile
import time
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .. import debug
from ..atomic import replace_atomically, write_text_atomic
from ..config import Settings
from ..engine.assets import ClipTemplate, is_search_path
from ..model import INTERNAL_ERROR_CODE, FileResult
from ..paths import usd_path
from ..records import record
from ..report_json import finding_from_dict, finding_to_dict
from ..settings_table import not_in_cache_key, settings_key

if TYPE_CHECKING:
    from ..engine import Linter
    from ..engine.assets import Reads
    from ..engine.variants import VariantExplorer

#: The default folder, at the project root (the config file's folder, else the
#: working directory).
CACHE_DIR_NAME = ".usdrender_lint_cache"
#: Bumped when an entry's layout changes; older entries are then foreign.
#: 2: entries keep the result's notes (--variants' skipped combinations); 3: real
#: paths, existence-only assets, search paths, resolver context, clip templates.
FORMAT = 3
ENTRIES_DIR = f"v{FORMAT}"
#: The name of an entry file: the only files pruning removes.
ENTRY_NAME = re.compile(r"[0-9a-f]{40}\.json")
#: The cache's size bound, and what pruning brings it down to.
MAX_BYTES = 256 << 20
PRUNE_TO = 3 * MAX_BYTES // 4
#: A result larger than this (a file with a huge number of findings) is not stored.
MAX_ENTRY_BYTES = 4 << 20
#: Settings that change what a report is used for, not any file's findings.
SETTINGS_NOT_IN_KEY = not_in_cache_key() | {
    "source",
    # Where the user's own configuration's globs are read from: in the key
    # through what reads them (profile_choice_key's base folder).
    "user_level",
    "from_flags",
    "from_file",
    "sources",
    "entries_from",
}
#: Environment prefixes that can change what USD composes (plugin and resolver
#: paths, USD's own switches). None of the linter's own variables: none
#: changes a finding (they say where the cache is, whether it is used, whether
#: a traceback is shown), and none steers how a file is linted.
ENV_PREFIXES = ("PXR_", "TF_", "USD_")
#: Written into the folder so that git and backup tools leave it alone.
_GITIGNORE = "# Created by usdrender-lint: the result cache.\n*\n"
_CACHEDIR_TAG = (
    "Signature: 8a477f597d28d172789f06886806bc55\n"
    "# This file is a cache directory tag created by usdrender-lint.\n"
)


def cache_folder(settings: Settings, given: str | os.PathLike[str] | None = None) -> Path:
    """The cache's folder: ``given`` (``--cache-dir``, relative to the working
    directory), else ``cache-dir`` from the configuration (relative to its
    file's folder), else ``.usdrender_lint_cache`` at the project root."""
    if given:
        return Path(given)
    if settings.cache_dir:
        return settings.base_dir / settings.cache_dir
    return settings.base_dir / CACHE_DIR_NAME


# -- the run key -------------------------------------------------------------------


def run_key(linter: Linter, settings: Settings, **extra: object) -> str:
    """The digest of everything that decides a file's findings besides the
    files themselves: the linter's rules and options, severities and
    composition, the settings, the tool and usd-core versions and code, and
    the environment. ``extra`` adds what else the caller's linter depends on
    (e.g. the variant combinations explored)."""
    from pxr import Usd

    rules = [
        (type(rule).__module__, type(rule).__qualname__, rule.code, repr(rule.options))
        for rule in linter.rules
    ]
    known = sorted(rule.code for rule in linter.known_rules or ())
    parts = {
        "format": FORMAT,
        # The package is imported (this module is in it); read, not imported, to keep
        # running below the package's __init__ (tests/api/test_import_layers.py).
        "tool": sys.modules["usdrender_lint"].__version__,
        "code": _code_signature(linter),
        "usd": [*Usd.GetVersion(), _usd_build()],
        "python": list(sys.version_info[:2]),
        "rules": rules,
        "known_rules": known,
        "severities": sorted((code, str(s)) for code, s in linter.severities.items()),
        "time_sample_cap": linter.time_sample_cap,
        "full_composition": linter.full_composition,
        "settings": settings_key(settings),
        "env": {
            name: value
            for name, value in sorted(os.environ.items())
            if name.startswith(ENV_PREFIXES)
        },
        "plugins": _plugin_signature(),
        "extra": extra,
    }
    return _digest_text(_canonical(parts))


def _usd_build() -> tuple[str, int, int] | None:
    """(path, size, mtime) of usd-core's compiled Usd module: another build of
    the same version (usd-core 25.5 and 25.5.1 both say 0.25.5, as does a
    studio's own build) installed in its place composes by its own code."""
    module = sys.modules.get("pxr.Usd._usd") or sys.modules["pxr.Usd"]
    path = getattr(module, "__file__", None)
    try:
        info = os.stat(path) if path else None
    except OSError:
        info = None
    return (path, info.st_size, info.st_mtime_ns) if path and info else None


def _plugin_signature() -> list[tuple[str, int, int]]:
    """(path, size, mtime) of every file below the folders ``PXR_PLUGINPATH_NAME``
    names (an entry names a folder, a ``plugInfo.json`` or a glob of either, as
    USD reads it), and below the folders and of the libraries their
    ``plugInfo.json`` files name, which may lie elsewhere (:func:`_named_by`):
    a schema or resolver plugin installed, removed or edited there changes
    what USD composes and which types exist. Read from the file system, not
    USD's plugin registry: a process that asks the registry starts USD's
    threads, and one that forks its workers must not have any
    (running/workers.py). At most MAX_PLUGIN_FILES files are listed."""
    import glob

    folders: set[str] = set()
    for entry in os.environ.get("PXR_PLUGINPATH_NAME", "").split(os.pathsep):
        for found in glob.glob(os.path.expanduser(entry), recursive=True) if entry else ():
            folders.add(found if os.path.isdir(found) else os.path.dirname(found))
    pending = sorted(folders)
    walked: set[str] = set()
    signature: dict[str, tuple[str, int, int]] = {}

    def add(path: str) -> bool:
        """Lists the file; False once MAX_PLUGIN_FILES are listed."""
        try:
            info = os.stat(path)
        except OSError:
            return True
        signature.setdefault(path, (path, info.st_size, info.st_mtime_ns))
        return len(signature) < MAX_PLUGIN_FILES

    while pending:
        folder = pending.pop(0)
        if os.path.normpath(folder) in walked:
            continue
        walked.add(os.path.normpath(folder))
        for root, dirs, names in os.walk(folder):
            dirs.sort()
            for name in sorted(names):
                if not add(os.path.join(root, name)):
                    return list(signature.values())
                if name != "plugInfo.json":
                    continue
                for named in _named_by(os.path.join(root, name)):
                    if os.path.isdir(named):
                        pending.append(named)
                    elif not add(named):
                        return list(signature.values())
    return list(signature.values())


def _named_by(info: str) -> list[str]:
    """The folders and files a ``plugInfo.json`` has USD read besides itself,
    relative to its folder: what its ``Includes`` globs match (USD reads the
    ``plugInfo.json`` files there), each plugin's resources
    (``Root``/``ResourcePath``: its ``generatedSchema.usda``) and library
    (``Root``/``LibraryPath``). A file USD cannot read names nothing (its
    registration problem is a note of its own)."""
    import glob

    data = read_bounded(info, 1 << 20, follow_links=True)  # USD follows a linked one
    try:
        # USD's plugInfo.json may hold comment lines, which start with '#'.
        lines = data.decode().splitlines() if data is not None else []
        parsed = json.loads("\n".join("" if s.lstrip().startswith("#") else s for s in lines))
    except ValueError:
        return []
    if not isinstance(parsed, dict):
        return []
    folder = os.path.dirname(info)
    named: list[str] = []
    includes, plugins = parsed.get("Includes"), parsed.get("Plugins")
    for pattern in includes if isinstance(includes, list) else ():
        if isinstance(pattern, str) and pattern:
            found = glob.glob(os.path.join(folder, pattern), recursive=True)
            named += (path if os.path.isdir(path) else os.path.dirname(path) for path in found)
    for plugin in plugins if isinstance(plugins, list) else ():
        if not isinstance(plugin, dict):
            continue
        root = os.path.join(folder, str(plugin.get("Root") or "."))
        named.append(os.path.join(root, str(plugin.get("ResourcePath") or ".")))
        if plugin.get("LibraryPath"):
            named.append(os.path.join(root, str(plugin["LibraryPath"])))
    return sorted(dict.fromkeys(named))


#: The most plugin files the run key lists (a plugin folder holds a few dozen).
MAX_PLUGIN_FILES = 10_000


def _canonical(value: object) -> str:
    return json.dumps(value, sort_keys=True, default=_plain, separators=(",", ":"))


def _plain(value: object) -> object:
    if isinstance(value, Mapping):
        return {str(k): v for k, v in value.items()}
    if isinstance(value, (set, frozenset)):
        return sorted(value, key=repr)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: getattr(value, f.name) for f in dataclasses.fields(value)}
    return repr(value)


def _code_signature(linter: Linter) -> list[tuple[str, int, int]]:
    """(file, size, mtime) of the tool's own files and of every rule's module
    and package: an edited rule, engine or data file (a source checkout, a
    plugin under development) changes the key even when the version does not."""
    files: set[str] = set()
    own = list(sys.modules["usdrender_lint"].__path__)
    for folder in own:
        files.update(_source_files(folder))
    packages: set[str] = set()
    for rule in (*linter.rules, *(linter.known_rules or ())):
        module = sys.modules.get(rule.__module__)
        if getattr(module, "__file__", None):
            files.add(module.__file__)  # type: ignore[union-attr, arg-type]
        # The rule's package: a module beside it that it imports (a plugin's
        # helpers) is its code too. A top-level module has none (its folder is
        # site-packages).
        packages.add(rule.__module__ if hasattr(module, "__path__") else "")
        packages.add(rule.__module__.rpartition(".")[0])
    for package in sorted(packages - {""}):
        for folder in getattr(sys.modules.get(package), "__path__", ()):
            if not any(_is_below(folder, mine) for mine in own):
                files.update(_source_files(folder))
    signature = []
    for path in sorted(files):
        try:
            info = os.stat(path)
        except OSError:
            continue
        signature.append((path, info.st_size, info.st_mtime_ns))
    return signature


def _source_files(folder: str) -> list[str]:
    """The files below a package's folder, at most MAX_PLUGIN_FILES: its Python
    modules and the data files they read (a plugin's list of allowed names, a
    schema its import registers); not its bytecode, hidden files or an
    editor's backups (``.x.py.swp``, ``x.py~``), which come and go as it is edited."""
    found: list[str] = []
    for root, dirs, names in os.walk(folder, followlinks=True):  # a checkout links rules/
        dirs[:] = sorted(d for d in dirs if not d.startswith((".", "__pycache__")))
        found += (
            os.path.join(root, n)
            for n in sorted(names)
            if not n.startswith(".") and not n.endswith((".pyc", "~"))
        )
        if len(found) >= MAX_PLUGIN_FILES:
            return found[:MAX_PLUGIN_FILES]
    return found


def _is_below(path: str, folder: str) -> bool:
    path, folder = os.path.abspath(path), os.path.abspath(folder)
    return os.path.commonpath([path, folder]) == folder


# -- digests -----------------------------------------------------------------------


def _digest_text(text: str) -> str:
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


#: A dependency's state when only its existence matters (a rule checked it).
PRESENT = "present"


class _Files:
    """Content digests and real paths of files, computed once per run while a
    file's size, times and inode stay the same (a shared sublayer is read once
    per run)."""

    def __init__(self) -> None:
        self._known: dict[str, tuple[tuple[int, int, int, int], str]] = {}
        self._folders: dict[str, str] = {}

    def state(self, path: str, existence_only: bool = False) -> str | None:
        """The file's digest (or PRESENT when only its existence is asked); None
        when it does not exist."""
        try:
            info = os.stat(path)
        except (FileNotFoundError, NotADirectoryError):
            return None
        except OSError as exc:
            return f"unreadable:{exc.errno}"
        if existence_only:
            return PRESENT
        if not stat.S_ISREG(info.st_mode):
            return f"not-a-file:{stat.S_IFMT(info.st_mode):o}"
        stamp = (info.st_size, info.st_mtime_ns, info.st_ctime_ns, info.st_ino)
        known = self._known.get(path)
        if known is not None and known[0] == stamp:
            return known[1]
        try:
            # O_NONBLOCK: a FIFO put in the file's place after the stat must not block.
            fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
        except OSError as exc:
            return f"unreadable:{exc.errno}"
        try:
            with open(fd, "rb") as handle:
                if not stat.S_ISREG(os.fstat(handle.fileno()).st_mode):
                    return "not-a-file"
                digest = hashlib.file_digest(handle, "sha256").hexdigest()
        except OSError as exc:
            return f"unreadable:{exc.errno}"
        self._known[path] = (stamp, digest)
        return digest

    def real(self, path: str) -> str:
        """``os.path.realpath(path)``, each folder's resolved once per run (a
        retargeted link, the file's or a folder's, gives another real path)."""
        folder, name = os.path.split(path)
        real_folder = self._folders.get(folder)
        if real_folder is None:
            real_folder = self._folders[folder] = os.path.realpath(folder)
        joined = os.path.join(real_folder, name)
        try:
            is_link = stat.S_ISLNK(os.lstat(joined).st_mode)
        except OSError:
            return joined
        return os.path.realpath(joined) if is_link else joined


def _cached_result(data: dict, file: str) -> FileResult | None:
    """The result an entry holds; None when it is malformed or another file's."""
    findings, notes = data["findings"], data["notes"]
    if not isinstance(findings, list) or not isinstance(notes, list):
        return None
    if not all(isinstance(note, str) for note in notes):
        return None
    result = FileResult(
        file, findings=tuple(finding_from_dict(f) for f in findings), notes=tuple(notes)
    )
    if any(f.location.file != file for f in result.findings):
        return None  # another file's findings
    return result


def _entry_bytes(document: dict[str, object]) -> bytes | None:
    """An entry as stored; None when it is too large. A name that is not UTF-8
    is stored as JSON's ``\\udcXX`` escapes, which read back as the same name."""
    try:
        data = json.dumps(document, ensure_ascii=False, separators=(",", ":")).encode()
    except UnicodeEncodeError:
        data = json.dumps(document, separators=(",", ":")).encode()
    return data if len(data) <= MAX_ENTRY_BYTES else None


# -- dependencies --------------------------------------------------------------------


@record(frozen=True)
class Dependencies:
    """What a lint's result depends on besides the run key, as checked on
    lookup: the content (or absence) of ``files``, the existence of ``assets``,
    what the resolver finds for ``searches`` in ``context``, and the files
    clip templates match."""

    files: tuple[str, ...]
    assets: tuple[str, ...] = ()
    #: The files of ``files`` that are layers the lint read (the others are
    #: where a layer could be found, and may be absent).
    layers: frozenset[str] = frozenset()
    searches: tuple[str, ...] = ()
    clip_templates: tuple[ClipTemplate, ...] = ()
    context: str = ""


def dependencies(reads: Reads, root: str | None = None) -> Dependencies | None:
    """What the result of linting ``root`` (the file as given) depends on, from
    what the lint read; None when that cannot be known exactly."""
    if not reads.complete:
        return None
    layers = _layer_files(reads.layers, root)
    targets = _files_of(reads.targets)
    assets = _files_of(i for i in reads.assets if not is_search_path(i))
    if layers is None or targets is None or assets is None:
        return None
    files, folders, found = layers
    read = frozenset(files)
    searches = {*reads.searches, *found}
    # Sdf anchors a search path next to the layer naming it when that file
    # exists: next to any layer read, the file must stay as it was.
    files.update(os.path.join(folder, search) for search in searches for folder in folders)
    files |= targets
    searches.update(i for i in reads.assets if is_search_path(i))
    if root is not None:
        files.discard(os.path.abspath(root))
    return Dependencies(
        files=tuple(sorted(files)),
        assets=tuple(sorted(assets - files)),
        layers=read,
        searches=tuple(sorted(searches)),
        clip_templates=tuple(reads.clip_templates),
        context=reads.context,
    )


def _layer_files(
    layers: Iterable[tuple[str, str, bool, bool]], root: str | None
) -> tuple[set[str], set[str], set[str]] | None:
    """The files of the layers read, the folders they are in, and the search
    paths among their names; None when a layer is not a file as linted."""
    files: set[str] = set()
    folders: set[str] = set()
    searches: set[str] = set()
    root_identifiers = {root, os.path.normpath(root), os.path.abspath(root)} if root else set()
    for identifier, real_path, anonymous, dirty in layers:
        if anonymous:
            continue  # the engine's session layer, or one a file format makes from a file
        if dirty:
            return None  # edited in memory: its file is not what was linted
        if identifier in root_identifiers:
            identifier = os.path.abspath(identifier)
        elif is_search_path(identifier):
            searches.add(identifier)  # found by the resolver: found where, next time?
            identifier = real_path
        path = _file_of(identifier)
        if path is None:
            return None
        files.add(path)
        if real_path and os.path.isabs(real_path):
            folders.add(os.path.dirname(real_path))
    return files, folders, searches


def _files_of(identifiers: Iterable[str]) -> set[str] | None:
    """The files behind ``identifiers``; None when one is not a plain file path."""
    files = set()
    for identifier in identifiers:
        path = _file_of(identifier)
        if path is None:
            return None
        files.add(path)
    return files


def _outer(identifier: str) -> str:
    """The package file of a package-relative identifier (``a.usdz[b.usda]``)."""
    return identifier[: identifier.index("[")] if identifier.endswith("]") else identifier


def _file_of(identifier: str) -> str | None:
    """The file on disk behind a layer identifier as named (symbolic links not
    followed), or None when it is not a plain file path (a URI for another
    resolver, file format arguments)."""
    if ":SDF_FORMAT_ARGS:" in identifier or not os.path.isabs(_outer(identifier)):
        return None
    return os.path.normpath(_outer(identifier))


def _resolver_state(root: str, searches: Sequence[str]) -> tuple[str, list[str]]:
    """The resolver context a stage of ``root`` is opened with (its repr), and
    what the resolver finds for each search path in it."""
    from pxr import Ar

    from ..engine import register_plugins
    from ..layers.files import resolver_context_key

    register_plugins()  # a warm run's first USD call: engine/plugins.py
    resolver = Ar.GetResolver()
    context = resolver.CreateDefaultContextForAsset(usd_path(os.path.abspath(root)))
    key = resolver_context_key(context)
    if not searches:
        return key, []
    with Ar.ResolverContextBinder(context):
        return key, [str(resolver.Resolve(search)) for search in searches]


# -- reading an entry ------------------------------------------------------------------


def read_bounded(
    path: str | os.PathLike[str], limit: int, follow_links: bool = False
) -> bytes | None:
    """The bytes of a regular file of at most ``limit`` bytes; None for
    anything else (a FIFO, a device, a folder, a symbolic link unless
    ``follow_links``, a larger file) or a file that cannot be read. Never
    blocks on a FIFO."""
    flags = os.O_RDONLY | os.O_NONBLOCK | (0 if follow_links else getattr(os, "O_NOFOLLOW", 0))
    try:
        fd = os.open(path, flags | getattr(os, "O_CLOEXEC", 0))
    except OSError:
        return None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode) or info.st_size > limit:
            return None
        chunks = []
        size = 0
        while size <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        return b"".join(chunks) if size <= limit else None
    except OSError:
        return None
    finally:
        os.close(fd)


def _is_ours(tag: Path) -> bool:
    data = read_bounded(tag, 4096)
    return (
        data is not None
        and data.startswith(_CACHEDIR_TAG.encode()[:43])
        and (b"usdrender-lint" in data)
    )


# -- the cache -------------------------------------------------------------------------


class ForeignFolder(Exception):
    """The cache folder asked for is not one the cache may write into."""


class ResultCache:
    """Entries for one run key in ``folder``. Picklable (worker processes
    store the results they lint); what a process learnt about digests stays
    in that process."""

    def __init__(self, folder: str | os.PathLike[str], key: str) -> None:
        self.folder = Path(folder)
        self.key = key
        self._files = _Files()
        self.stored = 0
        self.hits = 0

    def __getstate__(self) -> dict[str, object]:
        return {"folder": self.folder, "key": self.key}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__(state["folder"], state["key"])  # type: ignore[misc]

    @property
    def entries(self) -> Path:
        return self.folder / ENTRIES_DIR

    def prepare(self) -> str | None:
        """Make the folder ready: created here (with a ``CACHEDIR.TAG`` and a
        ``.gitignore``), or an empty folder (which gets the tag), or one holding
        our tag. Raises :class:`ForeignFolder` for any other folder (a user's,
        which the cache must never write into or prune); returns why the
        cache cannot be written, or None."""
        tag = self.folder / "CACHEDIR.TAG"
        try:
            if not self._create():
                self._claim(tag)
                if not tag.exists():
                    write_text_atomic(tag, _CACHEDIR_TAG)
            self.entries.mkdir(exist_ok=True)
            probe = self.entries / f".probe-{os.getpid()}"
            probe.write_bytes(b"")
            probe.unlink()
        except OSError as exc:
            return f"cannot write the result cache {self.folder}: {exc.strerror or exc}"
        return None

    def _create(self) -> bool:
        """Create the folder with its tag, ``.gitignore`` and entries folder in
        one rename (a concurrent run never sees it half made); False when it
        exists already."""
        if os.path.lexists(self.folder):
            return False
        self.folder.parent.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=f".{self.folder.name}.", dir=self.folder.parent))
        try:
            (staging / "CACHEDIR.TAG").write_text(_CACHEDIR_TAG, encoding="utf-8")
            # Only into a folder made here: in a user's, it would hide their files from git.
            (staging / ".gitignore").write_text(_GITIGNORE, encoding="utf-8")
            (staging / ENTRIES_DIR).mkdir()
            try:
                os.rename(staging, self.folder)
            except OSError:
                if not os.path.lexists(self.folder):
                    raise
                return False  # another run made it first
            return True
        finally:
            shutil.rmtree(staging, ignore_errors=True)

    def _claim(self, tag: Path) -> None:
        """Refuse a folder that is not the cache's: not a folder, or holding
        files and no CACHEDIR.TAG of ours."""
        if not self.folder.is_dir():
            raise ForeignFolder(f"the cache folder {self.folder} is not a folder")
        if _is_ours(tag):
            return
        if any(not e.name.startswith(".CACHEDIR.TAG.") for e in os.scandir(self.folder)):
            raise ForeignFolder(
                f"{self.folder} is not a usdrender-lint cache folder (it holds files and no "
                "CACHEDIR.TAG of ours): give --cache-dir or cache-dir a new or empty folder"
            )

    def _entry_path(self, file: str) -> Path:
        where = _canonical([self.key, os.getcwd(), file, os.path.realpath(file)])
        return self.entries / f"{_digest_text(where)[:40]}.json"

    # -- lookup --------------------------------------------------------------------

    def lookup(self, file: str) -> FileResult | None:
        """The stored result for ``file`` when everything it depends on is as
        it was; None otherwise (also for a missing, corrupt or foreign entry)."""
        if debug.enabled():
            return None  # every file linted, so that an internal error's traceback shows
        entry = self._entry_path(file)
        data = read_bounded(entry, MAX_ENTRY_BYTES)
        if data is None:
            return None
        try:
            result = self._valid(json.loads(data), file)
        except Exception:  # noqa: BLE001 - a cache problem never costs a result
            # Corrupt (a deeply nested one included), or what it names cannot be
            # looked at now: linted and stored again.
            result = None
        if result is None:
            return None
        self.hits += 1
        with contextlib.suppress(OSError):
            os.utime(entry)  # recently used: pruning keeps it
        return result

    def _valid(self, data: Any, file: str) -> FileResult | None:
        if not self._names(data, file) or not self._unchanged(data, file):
            return None
        return _cached_result(data, file)

    def _names(self, data: Any, file: str) -> bool:
        """Whether ``data`` is an entry of this format and run key for ``file``."""
        if not isinstance(data, dict) or data.get("usdrender_lint_cache") != FORMAT:
            return False
        if data.get("key") != self.key or data.get("file") != file:
            return False
        deps = data["deps"]
        # The entry is for this file: its first dependency is the file itself.
        return isinstance(deps, list) and bool(deps) and deps[0][0] == os.path.abspath(file)

    def _unchanged(self, data: dict, file: str) -> bool:
        """Whether everything the entry's result depends on is as it was."""
        for named, real, state in data["deps"]:
            if not isinstance(named, str) or self._files.real(named) != real:
                return False
            if self._files.state(named, existence_only=state == PRESENT) != state:
                return False
        for folder, pattern, matched in data["clips"]:
            if not _TEMPLATE_PATTERN.fullmatch(pattern) or clip_matches(folder, pattern) != matched:
                return False  # a pattern no template makes (assets.clip_template) is not run
        searches = data["searches"]
        context, found = _resolver_state(file, [search for search, _ in searches])
        return context == data["context"] and found == [where for _, where in searches]

    # -- store ---------------------------------------------------------------------

    def state(self, path: str) -> str | None:
        """A file's content digest now (None when it does not exist)."""
        return self._files.state(path)

    def store(
        self,
        file: str,
        result: FileResult,
        reads: Reads,
        started_ns: int,
        digest_before: str | None = None,
    ) -> bool:
        """Record a result linted from ``started_ns`` on (``digest_before``:
        the file's digest before the lint read it); False when it is not
        stored (not cacheable, a dependency changed while it was linted, or
        the folder cannot be written)."""
        if result.status != "linted" or any(f.code == INTERNAL_ERROR_CODE for f in result.findings):
            return False  # a rule that raised lost its findings: what made it raise may pass
        found = dependencies(reads, file)
        if found is None:
            return False
        deps = self._dependency_states(file, found, started_ns, digest_before)
        if deps is None:
            return False
        context, where = _resolver_state(file, found.searches)
        if found.context and found.context != context:
            return False  # opened in another resolver context than a lookup would see
        if any(_changed_since(path, started_ns) for path in where if path):
            return False  # found now, made while it was linted: the lint may have found another
        paths = [os.path.abspath(file), *found.files, *found.assets, *where]
        # The folder the cache is in changed as the cache was made, just before the lint.
        if _folder_moved_since(paths, started_ns, os.path.abspath(self.folder.parent)):
            return False  # a folder on the way renamed into place: its files keep older times
        document = {
            "usdrender_lint_cache": FORMAT,
            "key": self.key,
            "file": file,
            "deps": deps,
            "searches": [list(pair) for pair in zip(found.searches, where, strict=True)],
            "context": context,
            "clips": [[t.folder, t.pattern, list(t.matched)] for t in found.clip_templates],
            "findings": [finding_to_dict(f, layer_path=str) for f in result.findings],
            "notes": list(result.notes),
        }
        data = _entry_bytes(document)
        if data is None:
            return False
        try:
            replace_atomically(self._entry_path(file), lambda tmp: _write(tmp, data))
        except OSError:
            return False
        self.stored += 1
        return True

    def _dependency_states(
        self, file: str, found: Dependencies, started_ns: int, digest_before: str | None
    ) -> list[list[str | None]] | None:
        """Each file the result depends on with its real path and digest (an
        asset: whether it exists); None when one changed while it was linted."""
        root = os.path.abspath(file)
        after = self._files.state(root)
        if after is None or (digest_before is not None and after != digest_before):
            return None  # the file changed while it was linted
        deps: list[list[str | None]] = [[root, self._files.real(root), after]]
        for path in found.files:
            deps.append([path, self._files.real(path), self._files.state(path)])
            if deps[-1][2] is None and path in found.layers:
                return None  # a layer the lint read is gone: removed while it was linted
        for path in found.assets:
            deps.append([path, self._files.real(path), self._files.state(path, True)])
            if deps[-1][2] is None and _removed_since(path, started_ns):
                return None  # a rule may have found it before it was removed
        # After the digests: a change after the lint began and before a digest shows here.
        if any(_changed_since(path, started_ns) for path in (root, *found.files, *found.assets)):
            return None  # changed or replaced while it was linted: which version was read?
        return deps

    # -- size ----------------------------------------------------------------------

    def prune(self, max_bytes: int = MAX_BYTES, keep_bytes: int = PRUNE_TO) -> int:
        """Remove the least recently used entries while the folder holds more
        than ``max_bytes`` (down to ``keep_bytes``); returns how many. Only
        the cache's own entry files are counted and removed (by name, regular
        files only), and only in a folder holding our CACHEDIR.TAG."""
        if not _is_ours(self.folder / "CACHEDIR.TAG"):
            return 0
        # Entries of an older format are never read again: they go first.
        older = [self.folder / f"v{n}" for n in range(1, FORMAT)]
        sized = [e for f in (*older, self.entries) for e in _entry_files(f, f != self.entries)]
        total = sum(size for _, size, _ in sized)
        if total <= max_bytes:
            return 0
        removed = 0
        for _, size, path in sorted(sized):
            if total <= keep_bytes:
                break
            try:
                path.unlink()
            except OSError:
                continue
            total -= size
            removed += 1
        return removed


#: The cache's own files besides its entries: the temporary file of an
#: interrupted write (an entry's, the tag's: atomic.temporary_prefix, mkstemp's
#: eight characters, ``.tmp``) and the write probe.
_OWN_TEMPORARY = re.compile(
    r"\.(?:[0-9a-f]{40}\.json|CACHEDIR\.TAG)\.[A-Za-z0-9_]{8}\.tmp|\.probe-[0-9]+"
)
#: The entries folders of every format (older ones, and a newer version's).
_ENTRIES_FOLDER = re.compile(r"v[0-9]+")


@record(frozen=True)
class Cleared:
    """What :func:`clear` removed from a cache folder, and what it left."""

    folder: Path
    entries: int
    size: int
    #: Names in the folder that are not the cache's (so the folder stays).
    kept: tuple[str, ...]
    #: The cache's own files that could not be removed, each with why.
    failed: tuple[str, ...] = ()
    #: Entries that appeared while the folder was cleared: a check running
    #: meanwhile wrote them (so the folder, its tag and .gitignore stay).
    written: int = 0


def is_cache_folder(folder: Path) -> bool:
    """Whether ``folder`` holds the cache's CACHEDIR.TAG."""
    return _is_ours(folder / "CACHEDIR.TAG")


class _Clearing:
    """One :func:`clear`: what it removed, kept and failed to remove."""

    def __init__(self) -> None:
        self.entries = self.size = 0
        self.kept: list[str] = []
        self.failed: list[str] = []
        self.written = 0

    def remove(self, path: Path, name: str, size: int = -1) -> None:
        try:
            path.unlink()
        except FileNotFoundError:
            return
        except OSError as exc:
            self.failed.append(f"{name}: {exc.strerror or exc}")
            return
        if size >= 0:
            self.entries += 1
            self.size += size

    def remove_folder(self, path: Path, name: str) -> None:
        try:
            path.rmdir()
        except OSError as exc:
            self.failed.append(f"{name}: {exc.strerror or exc}")


def clear(folder: Path) -> Cleared:
    """Remove the cache in ``folder`` (``usdrender-lint clean``): its entries of
    every format, interrupted writes, its ``.gitignore`` and tag, then each
    folder left empty. Only the cache's own files, by name, as pruning does:
    another file stays, and so does the folder holding it (a linked folder
    stays too). Raises :class:`ForeignFolder` for a folder without our tag."""
    if not is_cache_folder(folder):
        raise ForeignFolder(
            f"{folder} is not a usdrender-lint cache folder (no CACHEDIR.TAG of ours)"
        )
    done = _Clearing()
    gitignore = None
    for item in _listing(folder):
        if item.is_dir(follow_symlinks=False) and _ENTRIES_FOLDER.fullmatch(item.name):
            _clear_entries(Path(item.path), f"{item.name}/", done)
        elif _OWN_TEMPORARY.fullmatch(item.name):
            done.remove(Path(item.path), item.name)
        elif _our_gitignore(item):
            gitignore = Path(item.path)
        elif item.name != "CACHEDIR.TAG":
            done.kept.append(item.name)
    # The .gitignore and the tag last: a folder cleared halfway is still
    # recognised as the cache's, and one a running check writes into stays
    # ignored by git.
    if gitignore is not None and not done.written:
        done.remove(gitignore, gitignore.name)
    if not done.kept and not done.failed and not done.written:
        done.remove(folder / "CACHEDIR.TAG", "CACHEDIR.TAG")
        if not done.failed and not folder.is_symlink():
            done.remove_folder(folder, str(folder))
    return Cleared(
        folder,
        done.entries,
        done.size,
        tuple(sorted(done.kept)),
        tuple(done.failed),
        done.written,
    )


def _clear_entries(entries: Path, prefix: str, done: _Clearing) -> None:
    """An entries folder: its entries and interrupted writes, then the folder
    once empty (another file in it is kept, with the folder)."""
    listed = _entry_files(entries, True)
    for _, size, path in listed:
        done.remove(path, prefix + path.name, size)
    removing = {path.name for _, _, path in listed}  # those still here failed
    others = False
    for item in _listing(entries):
        if ENTRY_NAME.fullmatch(item.name) and item.is_file(follow_symlinks=False):
            others = True
            if item.name not in removing:  # new since the listing: a running check's
                done.written += 1
        elif ENTRY_NAME.fullmatch(item.name):
            others = True  # not a regular file: not removed, as pruning does
            done.kept.append(prefix + item.name)
        elif _OWN_TEMPORARY.fullmatch(item.name):
            done.remove(Path(item.path), prefix + item.name)
        else:
            others = True
            done.kept.append(prefix + item.name)
    if not others and not any(f.startswith(prefix) for f in done.failed):
        done.remove_folder(entries, prefix)


def _our_gitignore(item: os.DirEntry[str]) -> bool:
    return item.name == ".gitignore" and read_bounded(item.path, 4096) == _GITIGNORE.encode()


def _listing(folder: Path) -> list[os.DirEntry[str]]:
    try:
        with os.scandir(folder) as found:
            return list(found)
    except OSError:
        return []


def _entry_files(folder: Path, stale: bool) -> list[tuple[int, int, Path]]:
    """(last use, size, path) of the entry files in ``folder``, by name and
    regular files only; a ``stale`` folder's count as the least recently used."""
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    found = []
    for name in names:
        if not ENTRY_NAME.fullmatch(name):
            continue
        path = folder / name
        try:
            info = path.lstat()
        except OSError:
            continue
        if stat.S_ISREG(info.st_mode):
            found.append((-1 if stale else info.st_mtime_ns, info.st_size, path))
    return found


#: The patterns assets.clip_template makes: a name's dot-separated parts, each
#: ``-?[0-9]+`` (a ``#`` group) or escaped text, so matching is linear in a name.
_TEMPLATE_PART = r"(?:-\?\[0-9\]\+|(?:\\.|[^\\.^$*+?{}\[\]|()])+)"
_TEMPLATE_PATTERN = re.compile(rf"{_TEMPLATE_PART}(?:\\\.{_TEMPLATE_PART})*")


def clip_matches(folder: str, pattern: str) -> list[str]:
    """The names in ``folder`` a clip template's pattern matches, sorted."""
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    return sorted(n for n in names if re.fullmatch(pattern, n))


def _changed_since(path: str, started_ns: int) -> bool:
    """True when ``path`` (the file, or the link naming it) changed after
    ``started_ns``. The change time, which no copy keeping times (``cp -p``,
    ``rsync -t``) or ``touch`` can set back, and which a rename sets. An
    absent path has not (its absence is what the entry records)."""
    try:
        changed = max(os.stat(path).st_ctime_ns, os.lstat(path).st_ctime_ns)
    except (FileNotFoundError, NotADirectoryError):
        return False
    except OSError:
        return True
    # At: the same tick as the start may be after it.
    return changed >= started_ns


def _folder_moved_since(paths: Sequence[str], started_ns: int, skipped: str = "") -> bool:
    """Whether a folder on the way to one of ``paths`` (below the folder they
    all share) changed after ``started_ns``: a folder renamed into place (a
    publish) holds files whose own change times predate the lint, so only the
    folder (its entry's change time, a link's if it is one) tells that the path
    now names another file. A file added to such a folder also counts: a miss
    on the next run, never a stale answer. ``skipped``: a folder not looked at."""
    named = [path for path in paths if path]
    try:
        top = os.path.commonpath([os.path.dirname(path) for path in named]) if named else ""
    except ValueError:  # paths on different drives
        top = ""
    folders: set[str] = set()
    for path in named:
        folder = os.path.dirname(path)
        while folder not in folders and folder != top and folder != os.path.dirname(folder):
            folders.add(folder)
            folder = os.path.dirname(folder)
    for folder in folders - {skipped}:
        try:
            changed = os.lstat(folder).st_ctime_ns
        except (FileNotFoundError, NotADirectoryError):
            continue  # absent now: the entry records what is absent below it
        except OSError:
            return True
        if changed >= started_ns:
            return True
    return False


def _removed_since(path: str, started_ns: int) -> bool:
    """Whether an absent ``path`` may have existed after ``started_ns``: its
    nearest existing folder changed since (a file removed changes its folder)."""
    folder = os.path.dirname(path)
    while folder != os.path.dirname(folder) and not os.path.isdir(folder):
        folder = os.path.dirname(folder)
    return _changed_since(folder, started_ns)


def lint_start_ns() -> int:
    """The time a lint begins, on the clock the kernel stamps change times
    with (Linux: the coarse real-time clock, up to a tick behind
    ``time.time_ns()``, so that an edit just after the start could otherwise
    seem to come before it). A change time at or after it is a change during
    the lint (:func:`_changed_since`)."""
    return time.clock_gettime_ns(COARSE_CLOCK) if COARSE_CLOCK is not None else time.time_ns()


#: Linux's CLOCK_REALTIME_COARSE (5), which Python names from 3.13 on.
COARSE_CLOCK = getattr(time, "CLOCK_REALTIME_COARSE", 5 if sys.platform == "linux" else None)


def _write(temporary: Path, data: bytes) -> None:
    # No fsync: a torn entry after a power cut is corrupt, and corrupt entries are ignored.
    with open(temporary, "wb") as stream:
        stream.write(data)


class CachingLinter:
    """A linter (or variant explorer) whose results are stored in a cache as
    they are linted, keyed on what each lint read (its LintRun's reads)."""

    def __init__(self, linter: Linter | VariantExplorer, cache: ResultCache) -> None:
        self.linter = linter
        self.cache = cache

    @property
    def raise_errors(self) -> bool:
        return self.linter.raise_errors

    def lint_path(self, path: str, *, full_composition: bool = False) -> FileResult:
        started = lint_start_ns()
        before = self.cache.state(os.path.abspath(path))
        run = self.linter.run_path(path, full_composition=full_composition, reads=True)
        try:
            if run.completed and run.reads is not None:
                self.cache.store(path, run.result, run.reads, started, before)
        except Exception:  # noqa: BLE001 - a cache problem never costs a result
            if self.raise_errors:
                raise
        return run.result


__all__ = [
    "CACHE_DIR_NAME",
    "cache_folder",
    "CachingLinter",
    "clear",
    "Cleared",
    "Dependencies",
    "dependencies",
    "ForeignFolder",
    "is_cache_folder",
    "read_bounded",
    "ResultCache",
    "run_key",
    "settings_key",
]
