"""The result cache: a file's findings are reused while nothing they depend on
has changed (``check`` uses it by default, like ruff's; ``--no-cache`` turns it off).

An entry is found by the **run key** (the tool's version and code, usd-core's
version, the rules that run with their options, the severities, every setting
that can change a finding, the environment that configures USD or the linter)
and the file as given with the working directory. It holds the file's result and
the **content digest of every file the lint read**: the root layer, its
sublayers, the references and payloads it reached, the value clips it opened,
the layers the fast path scanned (engine/linter.py ``Reads``), and, as "absent",
each asset an arc names that did not exist. An entry is used only when every
digest still matches, so an edit to a sublayer that 4,000 files share shows up
in all 4,000, and creating a missing reference target re-lints its users.
Results that are not known to be complete (a stage USD could not open, a file
the tool could not lint, a layer with unsaved edits or an asset path this module
cannot map to a file) are never stored.

Entries are one JSON file each, written atomically, so concurrent runs (CI
shards sharing a cache) never see half an entry; a corrupt or foreign file is
ignored (and replaced on the next store). The folder is bounded: after a run that
stored entries, the least recently used ones are removed beyond MAX_BYTES.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import json
import os
import stat
import sys
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..atomic import replace_atomically, write_text_atomic
from ..config import Settings
from ..model import FileResult
from ..paths import layer_file
from ..report_json import ReportFormatError, finding_from_dict, finding_to_dict
from ..settings_table import not_in_cache_key, settings_key

if TYPE_CHECKING:
    from ..engine import Linter
    from ..engine.linter import Reads

#: The default folder, at the project root (the config file's folder, else the
#: working directory).
CACHE_DIR_NAME = ".usdrender_lint_cache"
#: Bumped when an entry's layout changes; older entries are then foreign.
FORMAT = 2  # 2: entries keep the result's notes (--variants' skipped combinations)
ENTRIES_DIR = f"v{FORMAT}"
#: The cache's size bound, and what pruning brings it down to.
MAX_BYTES = 256 << 20
PRUNE_TO = 3 * MAX_BYTES // 4
#: A result larger than this (a file with a huge number of findings) is not stored.
MAX_ENTRY_BYTES = 4 << 20
#: Settings that change what a report is used for, not any file's findings.
SETTINGS_NOT_IN_KEY = not_in_cache_key() | {"source", "from_flags"}
#: Environment prefixes that can change what USD composes or what the rules
#: report (plugin and resolver paths, the linter's own switches).
ENV_PREFIXES = ("PXR_", "TF_", "USD_", "USDRENDER_LINT_")
#: ... except these, which only say where the cache is or whether it is used.
ENV_NOT_IN_KEY = frozenset(
    {"USDRENDER_LINT_CACHE_DIR", "USDRENDER_LINT_NO_CACHE", "USDRENDER_LINT_DEBUG"}
)
#: Written into the folder so that git and backup tools leave it alone.
_GITIGNORE = "# Created by usdrender-lint: the result cache.\n*\n"
_CACHEDIR_TAG = (
    "Signature: 8a477f597d28d172789f06886806bc55\n"
    "# This file is a cache directory tag created by usdrender-lint.\n"
)


def default_cache_dir(settings: Settings) -> Path:
    """``cache-dir`` from the configuration (relative to its file's folder),
    else ``.usdrender_lint_cache`` at the project root."""
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
        "usd": list(Usd.GetVersion()),
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
            if name.startswith(ENV_PREFIXES) and name not in ENV_NOT_IN_KEY
        },
        "extra": extra,
    }
    return _digest_text(_canonical(parts))


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
    """(file, size, mtime) of the tool's own Python files and of every rule's
    module: an edited rule or engine (a source checkout, a plugin under
    development) changes the key even when the version does not."""
    files: set[str] = set()
    for folder in sys.modules["usdrender_lint"].__path__:
        for root, dirs, names in os.walk(folder, followlinks=True):  # a checkout links rules/
            dirs[:] = [d for d in dirs if not d.startswith((".", "__pycache__"))]
            files.update(os.path.join(root, n) for n in names if n.endswith((".py", ".json")))
    for rule in (*linter.rules, *(linter.known_rules or ())):
        module = sys.modules.get(rule.__module__)
        if getattr(module, "__file__", None):
            files.add(module.__file__)  # type: ignore[union-attr, arg-type]
    signature = []
    for path in sorted(files):
        try:
            info = os.stat(path)
        except OSError:
            continue
        signature.append((path, info.st_size, info.st_mtime_ns))
    return signature


# -- digests -----------------------------------------------------------------------


def _digest_text(text: str) -> str:
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


class _Digests:
    """Content digests of files, computed once per process while a file's
    size, times and inode stay the same (a shared sublayer is read once per run)."""

    def __init__(self) -> None:
        self._known: dict[str, tuple[tuple[int, int, int, int], str]] = {}

    def of(self, path: str) -> str | None:
        """The file's digest; None when it does not exist."""
        try:
            info = os.stat(path)
        except (FileNotFoundError, NotADirectoryError):
            return None
        except OSError as exc:
            return f"unreadable:{exc.errno}"
        if not stat.S_ISREG(info.st_mode):
            return f"not-a-file:{stat.S_IFMT(info.st_mode):o}"
        stamp = (info.st_size, info.st_mtime_ns, info.st_ctime_ns, info.st_ino)
        known = self._known.get(path)
        if known is not None and known[0] == stamp:
            return known[1]
        try:
            with open(path, "rb") as handle:
                digest = hashlib.file_digest(handle, "sha256").hexdigest()
        except OSError as exc:
            return f"unreadable:{exc.errno}"
        self._known[path] = (stamp, digest)
        return digest


# -- dependencies --------------------------------------------------------------------


def dependencies(reads: Reads) -> list[str] | None:
    """The files a lint's result depends on (the layers it read and the files
    arcs name, found or not), or None when that cannot be known exactly."""
    if not reads.complete:
        return None
    if reads.targets and os.environ.get("PXR_AR_DEFAULT_SEARCH_PATH"):
        return None  # a search path could supply a missing asset from anywhere
    files: set[str] = set()
    for identifier, real_path, anonymous, dirty in reads.layers:
        if anonymous:
            continue  # the engine's session layer, or one a file format makes from a file
        if dirty:
            return None  # edited in memory: its file is not what was linted
        path = _file_of(real_path or identifier)
        if path is None:
            return None
        files.add(path)
    for identifier in reads.targets:
        path = _file_of(identifier)
        if path is None:
            return None
        files.add(path)
    return sorted(files)


def _outer(identifier: str) -> str:
    """The package file of a package-relative identifier (``a.usdz[b.usda]``)."""
    return identifier[: identifier.index("[")] if identifier.endswith("]") else identifier


def _file_of(identifier: str) -> str | None:
    """The file on disk behind a layer identifier, or None when it is not a
    plain file path (a URI for another resolver, file format arguments)."""
    if ":SDF_FORMAT_ARGS:" in identifier or not os.path.isabs(_outer(identifier)):
        return None
    path = layer_file(identifier)
    return str(path) if path is not None else None


# -- the cache -------------------------------------------------------------------------


class ResultCache:
    """Entries for one run key in ``folder``. Picklable (worker processes
    store the results they lint); what a process learnt about digests stays
    in that process."""

    def __init__(self, folder: str | os.PathLike[str], key: str) -> None:
        self.folder = Path(folder)
        self.key = key
        self._digests = _Digests()
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
        """Create the folder (with a ``.gitignore`` and ``CACHEDIR.TAG`` in it);
        returns why the cache cannot be written, or None."""
        try:
            self.entries.mkdir(parents=True, exist_ok=True)
            for name, text in (("CACHEDIR.TAG", _CACHEDIR_TAG), (".gitignore", _GITIGNORE)):
                marker = self.folder / name
                if not marker.exists():
                    write_text_atomic(marker, text)
            probe = self.entries / f".probe-{os.getpid()}"
            probe.write_bytes(b"")
            probe.unlink()
        except OSError as exc:
            return f"cannot write the result cache {self.folder}: {exc.strerror or exc}"
        return None

    def _entry_path(self, file: str) -> Path:
        where = _canonical([self.key, os.getcwd(), file, os.path.realpath(file)])
        return self.entries / f"{_digest_text(where)[:40]}.json"

    # -- lookup --------------------------------------------------------------------

    def lookup(self, file: str) -> FileResult | None:
        """The stored result for ``file`` when every file it depends on is as
        it was; None otherwise (also for a missing, corrupt or foreign entry)."""
        entry = self._entry_path(file)
        try:
            data = json.loads(entry.read_bytes())
            result = self._valid(data, file)
        except (OSError, ValueError, TypeError, KeyError, ReportFormatError):
            return None
        if result is None:
            return None
        self.hits += 1
        with contextlib.suppress(OSError):
            os.utime(entry)  # recently used: pruning keeps it
        return result

    def _valid(self, data: Any, file: str) -> FileResult | None:
        if not isinstance(data, dict) or data.get("usdrender_lint_cache") != FORMAT:
            return None
        if data.get("key") != self.key or data.get("file") != file:
            return None
        deps = data["deps"]
        if not isinstance(deps, list) or not deps:
            return None
        for path, digest in deps:
            if not isinstance(path, str) or self._digests.of(path) != digest:
                return None
        findings, notes = data["findings"], data["notes"]
        if not isinstance(findings, list) or not isinstance(notes, list):
            return None
        if not all(isinstance(note, str) for note in notes):
            return None
        return FileResult(
            file, findings=tuple(finding_from_dict(f) for f in findings), notes=tuple(notes)
        )

    # -- store ---------------------------------------------------------------------

    def store(self, file: str, result: FileResult, reads: Reads, started_ns: int) -> bool:
        """Record a result linted from ``started_ns`` on; False when it is not
        stored (not cacheable, a dependency changed while it was linted, or the
        folder cannot be written)."""
        if result.status != "linted":
            return False
        files = dependencies(reads)
        if not files:
            return False
        deps = []
        for path in files:
            digest = self._digests.of(path)
            if digest is not None and _modified_since(path, started_ns):
                return False  # edited while it was being linted: which version was read?
            deps.append([path, digest])
        document = {
            "usdrender_lint_cache": FORMAT,
            "key": self.key,
            "file": file,
            "deps": deps,
            "findings": [finding_to_dict(f, layer_path=str) for f in result.findings],
            "notes": list(result.notes),
        }
        text = json.dumps(document, ensure_ascii=False, separators=(",", ":"))
        if len(text) > MAX_ENTRY_BYTES:
            return False
        try:
            replace_atomically(self._entry_path(file), lambda tmp: _write(tmp, text))
        except OSError:
            return False
        self.stored += 1
        return True

    # -- size ----------------------------------------------------------------------

    def prune(self, max_bytes: int = MAX_BYTES, keep_bytes: int = PRUNE_TO) -> int:
        """Remove the least recently used entries while the folder holds more
        than ``max_bytes`` (down to ``keep_bytes``); returns how many."""
        try:
            names = os.listdir(self.entries)
        except OSError:
            return 0
        sized = []
        for name in names:
            path = self.entries / name
            try:
                info = path.stat()
            except OSError:
                continue
            sized.append((info.st_mtime_ns, info.st_size, path))
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


def _modified_since(path: str, started_ns: int) -> bool:
    try:
        return os.stat(path).st_mtime_ns > started_ns
    except OSError:
        return True


def _write(temporary: Path, text: str) -> None:
    # No fsync: a torn entry after a power cut is corrupt, and corrupt entries are ignored.
    with open(temporary, "w", encoding="utf-8") as stream:
        stream.write(text)


class CachingLinter:
    """A linter (or variant explorer) whose results are stored in a cache as
    they are linted; it has ``lint_path`` like the linter it wraps."""

    def __init__(self, linter: Any, cache: ResultCache) -> None:
        self.linter = linter
        self.cache = cache

    @property
    def rules(self) -> Sequence[Any]:
        return self.linter.rules

    @property
    def raise_errors(self) -> bool:
        return bool(getattr(self.linter, "raise_errors", False))

    def lint_path(self, path: str, *, full_composition: bool = False) -> FileResult:
        started = time.time_ns()
        with self.linter.recording_reads() as reads:
            result = (
                self.linter.lint_path(path, full_composition=True)
                if full_composition
                else self.linter.lint_path(path)
            )
        try:
            self.cache.store(path, result, reads, started)
        except Exception:  # noqa: BLE001 - a cache problem never costs a result
            if self.raise_errors:
                raise
        return result


__all__ = [
    "CACHE_DIR_NAME",
    "CachingLinter",
    "ResultCache",
    "default_cache_dir",
    "dependencies",
    "run_key",
    "settings_key",
]
