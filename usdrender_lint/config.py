"""Configuration: defaults < config file < command-line flags -> frozen Settings.

The file is ``[tool.usdrender-lint]`` in the nearest ``pyproject.toml`` or a
``.usdrender-lint.toml`` (top-level keys). Unknown keys and bad values are a
:class:`ConfigError` naming the key.
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import errno
import itertools
import os
import re
import stat
import time
import types
import typing
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from collections.abc import Set as AbstractSet
from dataclasses import field
from pathlib import Path
from typing import Any, TypeVar

from .model import Severity
from .records import record
from .settings_table import (
    BY_CONFIG_KEY,
    BY_NAME,
    DEFAULT_EXCLUDE,
    FAIL_ON_CHOICES,
    MAX_JOBS,
    MAX_TIMEOUT,
    MAX_VARIANT_COMBINATIONS,
    SETTINGS,
    ConfigError,
)

#: The names a folder's configuration file may have, the first found winning
#: (as ruff reads ``.ruff.toml``, ``ruff.toml``, then ``pyproject.toml``).
CONFIG_FILE_NAMES = (".usdrender-lint.toml", "usdrender-lint.toml", "pyproject.toml")
TOOL_TABLE = "usdrender-lint"

#: The settings that choose the rules, laid over each other as ruff's rule
#: selections are (``Settings.selections_below``).
SELECTION_KEYS = ("select", "ignore", "extend_select")


@record(frozen=True)
class RuleSelection:
    """The ``select``, ``ignore`` and ``extend-select`` of one layer of the
    configuration (a file extended, the file under the flags)."""

    select: tuple[str, ...] | None
    ignore: tuple[str, ...]
    extend_select: tuple[str, ...]
    #: Where each came from (``Settings.where``), for errors.
    origins: Mapping[str, str]


@record(frozen=True)
class Settings:
    #: Rules to run: codes, code prefixes or names ("ALL"); by default every rule.
    select: tuple[str, ...] | None = None
    #: Rules to skip: codes, code prefixes or names.
    ignore: tuple[str, ...] = ()
    #: Rules added to ``select``.
    extend_select: tuple[str, ...] = ()
    #: The lowest severity that fails the run (exit 1): error, warning, info or never.
    fail_on: str = "error"
    #: Severity overrides, keyed by rule code or name.
    severity: Mapping[str, Severity] = field(default_factory=dict)
    #: File glob -> codes, prefixes or names ignored in matching files.
    per_path_ignores: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    #: Rule name or code -> option values, validated against the rule's Options.
    rule_options: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    #: Globs of stage root files (changed layers are linted in their roots).
    roots: tuple[str, ...] = ()
    #: Cap on authored time samples evaluated per attribute.
    time_sample_cap: int = 1000
    #: Rules (codes, prefixes or names) whose fixes --fix never applies.
    unfixable: tuple[str, ...] = ()
    #: Also lint under other variant selections of the render prims (--variants).
    variants: bool = False
    #: The most variant combinations linted per file with ``variants``.
    max_variant_combinations: int = 64
    #: The renderer profile: "auto" (inferred per RenderSettings) or a name.
    profile: str = "auto"
    #: File glob -> profile name for matching files (wins over ``profile``).
    per_path_profiles: Mapping[str, str] = field(default_factory=dict)
    #: Gitignore-style patterns not linted when a folder is walked (the default replaced).
    exclude: tuple[str, ...] = DEFAULT_EXCLUDE
    #: Patterns excluded as well as ``exclude``'s.
    extend_exclude: tuple[str, ...] = ()
    #: Skip what .gitignore files ignore when a folder is walked.
    respect_gitignore: bool = True
    #: Skip a path given too where a folder walk would skip it.
    force_exclude: bool = False
    #: Where the result cache lives (relative to the config file's folder);
    #: None: ``.usdrender_lint_cache`` there (running/result_cache.py).
    cache_dir: str | None = None
    #: The configuration file the file starts from (its absolute path), whose
    #: settings are folded into these.
    extend: str | None = None
    #: The file the settings were read from, if any.
    source: str | None = None
    #: ``source`` is the user's own configuration (:func:`user_config_file`),
    #: read where no project configuration is found: its globs, roots and
    #: cache-dir are relative to the working directory, as ruff reads its own.
    user_level: bool = False
    #: Settings given as command-line flags (they win over the file).
    from_flags: frozenset[str] = frozenset()
    #: Settings a file sets, each with that file (the nearest that sets it, when
    #: one extends another): errors and ``check --show-settings`` name it.
    from_file: Mapping[str, str] = field(default_factory=dict)
    #: Every configuration file read: ``source``, then the files it extends.
    sources: tuple[str, ...] = ()
    #: (setting, entry) -> the file (or ``--config 'KEY = VALUE'``) holding that
    #: entry of a table or list a file extending another adds to: an error about
    #: one entry names the file it is in (``where_entry``).
    entries_from: Mapping[tuple[str, str], str] = field(default_factory=dict)
    #: The rule selections of the layers beneath ``select``, ``ignore`` and
    #: ``extend_select`` (the files extended, the file under the flags), first
    #: to last. Each layer starts from what the one beneath chose, as in ruff: a
    #: ``select`` of its own starts over; an ``ignore`` or ``extend-select``
    #: changes only the rules it names (registry.select_rules).
    selections_below: tuple[RuleSelection, ...] = ()

    def merged(self, **overrides: Any) -> Settings:
        """These settings with the non-None overrides applied (command-line flags),
        as a file that extends them would lay them over: ``--extend-exclude``
        adds to the configured list (as ruff's does), and the rule selection
        flags make a layer over the file's (``selections_below``)."""
        given = {k: v for k, v in overrides.items() if v is not None}
        values = _layered(self, given)
        return dataclasses.replace(self, **values, from_flags=self.from_flags | set(given))

    @property
    def selection_layers(self) -> tuple[RuleSelection, ...]:
        """Every layer of the rule selection, first to last: those beneath,
        then these settings' own ``select``, ``ignore`` and ``extend_select``."""
        own = RuleSelection(
            self.select,
            self.ignore,
            self.extend_select,
            {key: self.where(key) for key in SELECTION_KEYS},
        )
        return (*self.selections_below, own)

    def where(self, key: str) -> str:
        """Where a setting came from, for error messages: the flag or file and key."""
        if key in self.from_flags:
            return "--" + key.replace("_", "-")
        config_key = BY_NAME[key].config_key if key in BY_NAME else None
        return f"{self.from_file.get(key, self.source) or 'config'}: {config_key or key}"

    def where_entry(self, name: str, entry: str) -> str:
        """Where one entry of a table or list setting (``severity``'s ``SE003``,
        an ``unfixable`` code) came from: the file that holds it and the key."""
        holder = self.entries_from.get((name, entry))
        if holder is None:
            return self.where(name)
        return f"{holder}: {BY_NAME[name].config_key or name}"

    def nearest_first(self, name: str) -> list[tuple[str, Any]]:
        """The entries of a table setting, those of the nearest layer (the flags'
        inline settings, the file found, then the files it extends) first, each
        layer's in its own order: the first of per-path-profiles' globs that
        matches is the show's, not the studio's catch-all beneath it."""
        runs: list[list[tuple[str, Any]]] = []
        holder: object = object()
        for key, value in getattr(self, name).items():
            here = self.entries_from.get((name, str(key)))
            if not runs or here != holder:
                runs.append([])
                holder = here
            runs[-1].append((key, value))
        return [item for run in reversed(runs) for item in run]

    @property
    def base_dir(self) -> Path:
        """The folder relative globs (per-path-ignores) are read from: the
        config file's folder, else (none, or the user's own configuration)
        the working directory. The folder the file
        was found in, resolved: a show's ``.usdrender-lint.toml`` that links to a
        studio-wide file reads its globs, roots and cache-dir from the show."""
        if self.source and not self.user_level:
            return Path(self.source).parent.resolve()
        return Path.cwd()


def _parse_table(
    table: Mapping[str, Any],
    source: str,
    prefix: str = "",
    chain: tuple[str, ...] = (),
    text: str = "",
) -> Settings:
    """Settings from the config table (each key as the settings table reads
    it); ``prefix`` qualifies key names in errors (``tool.usdrender-lint.`` in
    a pyproject). ``chain``: the files that extend this one, for cycles.
    ``text``: the file's, where an error finds the line of its key."""
    parsed: dict[str, Any] = {}
    for key, value in table.items():
        with _at_key_line(source, text, prefix, key):
            entry = BY_CONFIG_KEY.get(key)
            if entry is None:
                raise ConfigError(
                    f"{source}: unknown key '{prefix + key}'{_hint(key, value, prefix)}"
                )
            parsed[entry.name] = entry.parse(value, f"{source}: '{prefix + key}'")
    if "extend" in parsed:
        with _at_key_line(source, text, prefix, "extend"):
            return _extending(parsed, source, prefix, chain)
    return Settings(
        **parsed,
        source=source,
        from_file=dict.fromkeys(parsed, source),
        sources=(source,),
        entries_from=_entries(parsed, source),
    )


def _entries(parsed: Mapping[str, Any], holder: str) -> dict[tuple[str, str], str]:
    """(setting, entry) -> ``holder`` for each entry of the tables and lists that
    a file extending this one adds to rather than replaces."""
    return {
        (name, str(entry)): holder
        for name, value in parsed.items()
        if BY_NAME[name].extended != "replaced"
        for entry in value
    }


#: ruff's names of keys that are spelt otherwise here.
_RUFF_KEYS = {
    "per-file-ignores": "per-path-ignores",
    # extend merges per-path-ignores entry by entry: what ruff's extend- form does.
    "extend-per-file-ignores": "per-path-ignores",
    "extend-ignore": "ignore",
    "rule-options": "rules",
}


def _hint(key: str, value: Any, prefix: str) -> str:
    """What an unknown key of a file means: a pyproject's table copied whole
    into a file of top-level keys, a key ruff spells so, or a misspelling."""
    if not prefix and key == "tool" and isinstance(value, Mapping) and TOOL_TABLE in value:
        return (
            f" (this file holds the keys at the top level: drop the [tool.{TOOL_TABLE}] "
            "header, which only a pyproject.toml has)"
        )
    if key == "lint" and isinstance(value, Mapping):
        # ruff keeps its rule settings in a [lint] table
        # (https://docs.astral.sh/ruff/settings/#lint): here there is none.
        where = f"in [{prefix.rstrip('.')}] itself" if prefix else "at the top level"
        return f" (ruff's [lint] table: here its keys are {where})"
    return unknown_key_hint(key)


def unknown_key_hint(key: str) -> str:
    """`` (did you mean 'KEY'?)`` for a key ruff spells so or a near misspelling."""
    import difflib  # only for an error

    near = _RUFF_KEYS.get(str(key)) or next(
        iter(difflib.get_close_matches(str(key), list(BY_CONFIG_KEY), n=1, cutoff=0.75)), None
    )
    return f" (did you mean '{near}'?)" if near else ""


@contextlib.contextmanager
def _at_key_line(source: str, text: str, prefix: str, key: str) -> Iterator[None]:
    """A ConfigError of ``source``'s ``key`` names the line the key is on too
    (``file:line: 'key' ...``), as a TOML syntax error names its line."""
    try:
        yield
    except ConfigError as exc:
        message, head = str(exc), f"{source}: "
        path = (*(part for part in prefix.split(".") if part), key)
        if not message.startswith(head):
            raise
        # An entry's error ('severity.SE003' must be ...) names the entry's line.
        entry = message[len(head) :].partition("' ")[0].removeprefix(f"'{prefix}{key}.")
        line = key_line(text, (*path, entry)) if entry != message[len(head) :] else None
        line = line or key_line(text, path)
        if line is None:
            raise
        raise ConfigError(f"{source}:{line}: {message[len(head) :]}") from None


#: One part of a dotted TOML key: bare, "basic" or 'literal'.
_KEY_PART = r"""(?:[A-Za-z0-9_-]+|"(?:[^"\\]|\\.)*"|'[^']*')"""
_DOTTED_KEY = rf"{_KEY_PART}(?:\s*\.\s*{_KEY_PART})*"
#: Patterns, not compiled ones: only an error looks for its line (re keeps them once compiled,
#: and compiling them at import cost every run's start-up).
_TABLE_LINE = rf"\s*\[\[?\s*({_DOTTED_KEY})\s*\]"
_KEY_LINE = rf"\s*({_DOTTED_KEY})\s*="


def _key_parts(dotted: str) -> tuple[str, ...]:
    parts = []
    for part in re.findall(_KEY_PART, dotted):
        if part.startswith('"'):
            import json  # an error's line only: not at every start-up

            try:
                part = json.loads(part)  # TOML's basic-string escapes are JSON's
            except ValueError:
                part = part[1:-1]
        elif part.startswith("'"):
            part = part[1:-1]
        parts.append(part)
    return tuple(parts)


def key_line(text: str, key: tuple[str, ...]) -> int | None:
    """The first line (1-based) of ``text`` (TOML) that sets ``key`` or a key
    below it (``[severity]``, ``severity.SE003 = ...``); None if not found.
    A scan of the lines, not a parser: tomllib says where no key is."""
    table: tuple[str, ...] = ()
    closing = ""  # the quotes that end the multi-line string being skipped
    for number, line in enumerate(text.splitlines(), 1):
        if closing:
            closing = "" if line.count(closing) % 2 else closing
            continue
        header = re.match(_TABLE_LINE, line)
        assigned = None if header else re.match(_KEY_LINE, line)
        if header:
            table = _key_parts(header.group(1))
            full = table
        elif assigned:
            full = table + _key_parts(assigned.group(1))
            for quotes in ('"""', "'''"):
                if line.count(quotes) % 2:
                    closing = quotes
        else:
            continue
        if full[: len(key)] == key:
            return number
    return None


def with_key_line(message: str, settings: Settings) -> str:
    """``message`` (``FILE: KEY...: why``, an error found once the rules are
    known: a code that names no rule, a rule's option) with the line of its
    key in FILE (``FILE:LINE: KEY...``), as the errors found reading the file
    say it; unchanged when FILE is none of ``settings``' files or the key is
    not found."""
    for source in settings.sources:
        head = f"{source}: "
        if not message.startswith(head):
            continue
        rest = message[len(head) :]
        key = rest.split(": ", 1)[0]
        top, _, entry = key.partition(".")
        prefix: tuple[str, ...] = (
            ("tool", TOOL_TABLE) if Path(source).name == "pyproject.toml" else ()
        )
        try:
            text = _load_toml_text(Path(source))[1]
        except ConfigError:
            return message
        # An entry's name may hold dots (a glob, "rules.SE001.require-authored").
        tries: list[tuple[str, ...]] = [(top,)]
        if entry:
            tries[:0] = [(top, entry), (top, *entry.split(".")), (top, entry.rsplit(".", 1)[0])]
            option = re.search(r"unknown option '([^']*)'", rest)
            if option:  # the option's own line
                tries.insert(0, (top, *entry.split("."), option.group(1)))
        for path in tries:
            line = key_line(text, (*prefix, *path))
            if line is not None:
                return f"{source}:{line}: {rest}"
        return message
    return message


#: The most files a chain of ``extend`` reads: each is read inside the one
#: extending it, and a few hundred overflowed Python's stack (an internal error).
MAX_EXTEND_DEPTH = 64


def _extending(
    parsed: dict[str, Any], source: str, prefix: str, chain: tuple[str, ...]
) -> Settings:
    """The settings of ``source``, which extends another file: that file's,
    with each key ``source`` sets replacing, merging or adding to its value as
    the settings table says (``Setting.extended``)."""
    # ~ and variables are expanded as the value is read (settings_table.expand_path).
    target = Path(os.path.abspath(Path(source).parent / parsed["extend"]))
    here = (*chain, os.path.realpath(source))
    if os.path.realpath(target) in here:
        cycle = " -> ".join([*chain, source, str(target)])
        raise ConfigError(f"{source}: '{prefix}extend' makes a cycle: {cycle}")
    if len(here) >= MAX_EXTEND_DEPTH:
        raise ConfigError(
            f"{source}: '{prefix}extend': more than {MAX_EXTEND_DEPTH} files extend each other "
            f"(from {here[0]})"
        )
    if not os.path.lexists(target):
        raise ConfigError(f"{source}: '{prefix}extend': no such file: {target}")
    if os.path.isdir(target):
        raise ConfigError(
            f"{source}: '{prefix}extend': a folder, not a configuration file: {target}"
        )
    base = read_config_file(target, chain=here)
    values = _layered(base, parsed)
    values["extend"] = str(target)
    return dataclasses.replace(
        base,
        **values,
        source=source,
        from_file={**base.from_file, **dict.fromkeys(parsed, source)},
        sources=(source, *base.sources),
        entries_from={**base.entries_from, **_entries(parsed, source)},
    )


def _layered(base: Settings, parsed: Mapping[str, Any]) -> dict[str, Any]:
    """The values of ``parsed`` laid over ``base``: each key replacing, merging
    or adding to ``base``'s as the settings table says (``Setting.extended``);
    a rule selection of its own puts ``base``'s beneath it."""
    values: dict[str, Any] = {}
    for name, value in parsed.items():
        how = BY_NAME[name].extended
        inherited = getattr(base, name)
        if how == "merged":
            value = _merged(inherited, value, deep=name == "rule_options")
        elif how == "added":
            value = (*inherited, *value)
        values[name] = value
    if any(key in parsed for key in SELECTION_KEYS):
        # base's own selection goes beneath, unless it is the defaults' alone.
        unset = not base.selections_below and base.select is None
        unset = unset and not base.ignore and not base.extend_select
        values["selections_below"] = () if unset else base.selection_layers
        for key in SELECTION_KEYS:
            values.setdefault(key, BY_NAME[key].default)
    return values


#: How an inline override is named where a file would be (errors, --show-settings).
INLINE_PREFIX = "--config '"


def is_inline(value: str) -> bool:
    """Whether a ``--config`` value is an inline ``KEY = VALUE`` (as ruff reads
    it), not a file: it holds ``=`` and names no existing file."""
    return "=" in value and not os.path.lexists(value)


#: How the language server's ``configuration`` table is named (errors).
EDITOR_SETTINGS = "the editor's configuration"


def with_inline(
    settings: Settings,
    overrides: Sequence[str | Mapping[str, Any]],
    table_name: str = EDITOR_SETTINGS,
    file_hint: str = "give it as --config FILE",
) -> Settings:
    """``settings`` with each ``--config 'KEY = VALUE'`` (TOML) or table (the
    editor's, the Python API's) laid over them, in order, as a file that
    extends them would be: ``severity.SE003 = "info"`` changes that entry,
    ``extend-select`` adds. Errors name the override (a table: ``table_name``);
    ``file_hint`` says how the caller gives a file instead of ``extend``."""
    for given in overrides:
        if isinstance(given, Mapping):
            where, table = table_name, given
        else:
            where, table = f"{INLINE_PREFIX}{given}'", _inline_table(given)
        parsed: dict[str, Any] = {}
        for key, value in table.items():
            entry = BY_CONFIG_KEY.get(key)
            if entry is None:
                raise ConfigError(f"{where}: unknown key '{key}'{unknown_key_hint(key)}")
            if entry.name == "extend":
                raise ConfigError(f"{where}: 'extend' names a file: {file_hint}")
            parsed[entry.name] = entry.parse(value, f"{where}: '{key}'")
        settings = dataclasses.replace(
            settings,
            **_layered(settings, parsed),
            from_file={**settings.from_file, **dict.fromkeys(parsed, where)},
            entries_from={**settings.entries_from, **_entries(parsed, where)},
        )
    return settings


def _inline_table(text: str) -> dict[str, Any]:
    import tomllib  # only when there is an override to read

    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        where = f"{INLINE_PREFIX}{text}'"
        raise ConfigError(f"{where}: neither a file nor TOML 'KEY = VALUE': {exc}") from None


def _merged(base: Mapping[str, Any], own: Mapping[str, Any], deep: bool) -> dict[str, Any]:
    """``base`` with ``own``'s entries; ``deep``: two tables of one key merge too.
    ``own``'s entries come last, those ``base`` had too included: a rule named
    by its code in one layer and by its name in another takes the later
    layer's value (severity_overrides and the rules' options read in order)."""
    merged = dict(base)
    for key, value in own.items():
        if deep and isinstance(merged.get(key), Mapping):
            value = {**merged[key], **value}
        merged.pop(key, None)
        merged[key] = value
    return merged


#: A config file larger than this is refused, not read (``--config /dev/zero``
#: read until the kernel killed the process).
MAX_CONFIG_BYTES = 4 * 1024 * 1024


#: The configuration files read in the current run (:func:`reading_once`), by
#: absolute path: None outside one.
_READ: contextvars.ContextVar[dict[str, bytes] | None] = contextvars.ContextVar(
    "usdrender_lint_config_read", default=None
)
#: Their TOML documents and texts, parsed once in the run.
_PARSED: contextvars.ContextVar[dict[str, tuple[dict[str, Any], str]] | None] = (
    contextvars.ContextVar("usdrender_lint_config_parsed", default=None)
)


@contextlib.contextmanager
def reading_once() -> Iterator[None]:
    """Within it, each configuration file is read and parsed once: a run's search for its
    configuration, each walked folder's exclusions and each part of a split run
    ask for a nested configuration's file again (four to six reads of each).
    Scoped to one run (a check, a --show-files): a long-running host reads
    again each time it prepares, so it sees a file edited since."""
    if _READ.get() is not None:  # already inside one: the outer run's files
        yield
        return
    token, parsed = _READ.set({}), _PARSED.set({})
    try:
        yield
    finally:
        _PARSED.reset(parsed)
        _READ.reset(token)


_Answer = TypeVar("_Answer")


def _once(
    memo: contextvars.ContextVar[dict[str, _Answer] | None],
    path: Path,
    compute: Callable[[Path], _Answer],
) -> _Answer:
    """``compute(path)``; inside :func:`reading_once`, computed the first time only."""
    done = memo.get()
    if done is None:
        return compute(path)
    key = os.path.abspath(path)
    if key not in done:
        done[key] = compute(path)
    return done[key]


def _read_config_bytes(path: Path) -> bytes:
    """The bytes of a config file, which must be a regular file (a FIFO would
    block, a device never end) of at most MAX_CONFIG_BYTES; inside
    :func:`reading_once`, read only the first time."""
    return _once(_READ, path, _read_config_file_bytes)


def _read_config_file_bytes(path: Path) -> bytes:
    try:
        # O_NONBLOCK: opening a FIFO returns at once instead of waiting for a writer.
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        reason = exc.strerror or str(exc)
        if path.is_symlink() and not path.exists():
            reason = "a symbolic link to nothing" if exc.errno != errno.ELOOP else reason
        raise ConfigError(f"{path}: cannot read config file: {reason}") from None
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        os.close(fd)
        kind = "a folder" if stat.S_ISDIR(mode) else "not a regular file"
        raise ConfigError(f"{path}: cannot read config file: {kind}")
    with os.fdopen(fd, "rb") as handle:
        try:
            data = handle.read(MAX_CONFIG_BYTES + 1)
        except OSError as exc:
            raise ConfigError(f"{path}: cannot read config file: {exc.strerror or exc}") from None
    if len(data) > MAX_CONFIG_BYTES:
        raise ConfigError(
            f"{path}: cannot read config file: larger than {MAX_CONFIG_BYTES // 1024 // 1024} MiB"
        )
    return data


def _load_toml(path: Path) -> dict[str, Any]:
    """The file's TOML document. A file that cannot be read or is not TOML is a
    ConfigError, with ``file:line:col`` of the first error."""
    return _load_toml_text(path)[0]


def _load_toml_text(path: Path) -> tuple[dict[str, Any], str]:
    """The file's TOML document and its text (see :func:`_load_toml`);
    inside :func:`reading_once`, parsed only the first time (each caller
    gets a copy of the document)."""
    if _PARSED.get() is None:
        return _parse_toml_file(path)
    document, text = _once(_PARSED, path, _parse_toml_file)
    import copy  # only inside a run that reads a file twice

    return copy.deepcopy(document), text


def _parse_toml_file(path: Path) -> tuple[dict[str, Any], str]:
    import tomllib  # only when there is a file to read

    data = _read_config_bytes(path)
    # A byte order mark (Windows editors write one) is no TOML statement: read past it.
    data = data.removeprefix(b"\xef\xbb\xbf")
    try:
        text = data.decode("utf-8")
        return tomllib.loads(text), text
    except UnicodeDecodeError as exc:
        line, column = _position(data[: exc.start].decode("utf-8"))
        reason = f"not UTF-8 (byte 0x{data[exc.start]:02x})"
    except tomllib.TOMLDecodeError as exc:
        line, column = _toml_error_position(exc, text)
        reason = re.sub(_TOML_POSITION, "", str(exc))
    except RecursionError:
        raise ConfigError(f"{path}: invalid TOML: arrays or tables nested too deeply") from None
    raise ConfigError(f"{path}:{line}:{column}: invalid TOML: {reason}")


#: Where tomllib says its error is (Python 3.11 puts it in the message only).
#: (Pattern text: re compiles it at first use, not at every start-up.)
_TOML_POSITION = r"\s*\((?:at line (\d+), column (\d+)|at end of document)\)$"


def _toml_error_position(exc: Exception, text: str) -> tuple[int, int]:
    if getattr(exc, "lineno", None) and getattr(exc, "colno", None):
        return exc.lineno, exc.colno  # type: ignore[attr-defined]
    found = re.search(_TOML_POSITION, str(exc))
    if found and found.group(1):
        return int(found.group(1)), int(found.group(2))
    return _position(text)  # the end of the document


def _position(text: str) -> tuple[int, int]:
    """(line, column) of the character just after ``text``, 1-based."""
    return text.count("\n") + 1, len(text) - (text.rfind("\n") + 1) + 1


def read_config_file(path: str | os.PathLike[str], chain: tuple[str, ...] = ()) -> Settings:
    """Read settings from a ``pyproject.toml`` or a ``.usdrender-lint.toml``
    (any other name is read as the latter). ``chain``: the files extending it."""
    path = Path(path)
    data, text = _load_toml_text(path)
    if path.name != "pyproject.toml":
        return _parse_table(data, str(path), chain=chain, text=text)
    tool = data.get("tool", {})
    if not isinstance(tool, dict) or TOOL_TABLE not in tool:
        extended_by = f" (which {chain[-1]} extends)" if chain else ""
        raise ConfigError(f"{path}: no [tool.{TOOL_TABLE}] table{extended_by}")
    if not isinstance(tool[TOOL_TABLE], dict):
        raise ConfigError(f"{path}: 'tool.{TOOL_TABLE}' must be a table")
    prefix = f"tool.{TOOL_TABLE}."
    return _parse_table(tool[TOOL_TABLE], str(path), prefix=prefix, chain=chain, text=text)


def find_config_file(start: str | Path) -> Path | None:
    """The nearest config file from ``start`` upwards. A ``pyproject.toml``
    counts only when it has a ``[tool.usdrender-lint]`` table; one that cannot
    be read or is not TOML stops the search (ConfigError): it may hold the
    table, and the run must not silently fall back to the defaults."""
    here = search_start(start)
    for folder in (here, *here.parents):
        found = config_file_in(folder)
        if found is not None:
            return found
    return None


#: The folder of the user's own configuration inside the platform's
#: configuration folder (``~/.config/usdrender-lint``).
USER_CONFIG_FOLDER = "usdrender-lint"


def user_config_dir() -> Path | None:
    """The folder that holds the user's own configuration file, as ruff finds
    ``~/.config/ruff`` (its ``find_user_settings_toml``, through etcetera's
    ``choose_base_strategy``: XDG on Linux and macOS, the roaming AppData
    folder on Windows): ``$XDG_CONFIG_HOME/usdrender-lint`` when that variable
    is an absolute path (the XDG Base Directory specification ignores a
    relative one), else ``~/.config/usdrender-lint``; on Windows
    ``%APPDATA%/usdrender-lint``. None when no home folder is known."""
    if os.name == "nt":
        appdata = os.environ.get("APPDATA")
        if appdata:
            return Path(appdata) / USER_CONFIG_FOLDER
    xdg = os.environ.get("XDG_CONFIG_HOME", "")
    if xdg and os.path.isabs(xdg):
        return Path(xdg) / USER_CONFIG_FOLDER
    try:
        home = Path.home()
    except (RuntimeError, KeyError):  # no HOME and no password entry
        return None
    if os.name == "nt":
        return home / "AppData" / "Roaming" / USER_CONFIG_FOLDER
    return home / ".config" / USER_CONFIG_FOLDER


def user_config_file() -> Path | None:
    """The user's own configuration file, read when no project configuration
    is found (the names a project folder's may have, in the same order; a
    ``pyproject.toml`` counts with the table only). A file there that cannot be
    read is a ConfigError, as a project's is."""
    folder = user_config_dir()
    if folder is None or not os.path.isdir(folder):
        return None
    return config_file_in(folder)


def read_user_config(path: str | os.PathLike[str]) -> Settings:
    """The settings of the user's own configuration file (see :func:`user_config_file`)."""
    return dataclasses.replace(read_config_file(path), user_level=True)


#: What tells a rewritten file from the one read: its size, modification
#: time, change time and inode, and 0 or, when the stamp alone cannot prove the
#: file unchanged later, a digest of its bytes or a number no other stamp has
#: (see :func:`stat_state`). None: gone or unreadable.
FileState = tuple[int, int, int, int, int] | None
#: Stamps of the files a host read, in the order it compares them.
Stamps = tuple[tuple[str, FileState], ...]

#: How long after a file's last change a stamp of it stays racy: a filesystem
#: timestamps from a clock that ticks (Linux's every few milliseconds, Windows'
#: every 15.6), so a second write within that tick keeps the first one's times.
RACY_NS = 100_000_000
#: The same for a filesystem that keeps whole seconds (HFS+, ext3) or two (FAT).
RACY_COARSE_NS = 2_000_000_000
#: The fifth field of racy stamps that carry no digest: -1, -2, ... (a digest is > 0).
_racy_serial = itertools.count(1)
_T = TypeVar("_T")


def file_state(path: str | None, *, racy: bool = True, read_ns: int | None = None) -> FileState:
    """The file's :data:`FileState`. Not its modification time alone: a file
    rewritten with that time kept (set back by a copy that keeps times, or
    written within one tick of a coarse clock) has another change time, and
    one renamed into place another inode. ``read_ns``: see :func:`stat_state`
    (None: the file is read after this stamp, if at all, so a racy stamp
    carries a digest of its bytes). ``racy=False``: the stamp as it is, even
    taken as the file changed (for a watch that hears the writes)."""
    if not path:
        return None
    try:
        info = os.stat(path)
    except OSError:
        return None
    if not racy:
        return (info.st_size, info.st_mtime_ns, info.st_ctime_ns, info.st_ino, 0)
    return stat_state(info, read_ns, path if read_ns is None else None)


def stat_state(
    info: os.stat_result, read_ns: int | None = None, digest_of: str | None = None
) -> tuple[int, int, int, int, int]:
    """The :data:`FileState` of a file whose ``os.stat`` is ``info``, read from
    ``read_ns`` on (``time.time_ns()``; default: now, the file read after).

    A write within the same clock tick as the last one, with the same size,
    leaves every field as it was: a stamp of a file whose last change
    (modification or change time, whichever is later) is not a tick older than
    its read cannot prove that what is there later is what was read. Git
    treats an index entry whose time is not older than the index file itself
    the same way, and compares such "racily clean" entries by content
    (git's Documentation/technical/racy-git.txt). So does a racy stamp here
    when the file is read after it (``digest_of``, the file's path): it carries
    a digest of the bytes. Else (taken after the read, or given no path) it
    matches no other stamp, so the next look reads the file again; that
    read's stamp is settled once the tick is over. A file dated ahead of this
    clock stays racy: it is compared by its digest where there is one.
    """
    mtime, ctime = info.st_mtime_ns, info.st_ctime_ns
    read = time.time_ns() if read_ns is None else read_ns
    coarse = mtime % 1_000_000_000 == 0 and ctime % 1_000_000_000 == 0
    mark = 0
    if max(mtime, ctime) >= read - (RACY_COARSE_NS if coarse else RACY_NS):
        digest = _digest(digest_of) if digest_of is not None else None
        mark = digest if digest is not None else -next(_racy_serial)
    return (info.st_size, mtime, ctime, info.st_ino, mark)


def _digest(path: str) -> int | None:
    """A positive digest of the regular file's bytes (None: unreadable, or not
    a regular file: a FIFO's reader would wait for a writer)."""
    import hashlib  # only for a racy stamp: not on start-up's path

    hashed = hashlib.blake2b(digest_size=8)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    try:
        with open(os.open(path, flags | getattr(os, "O_CLOEXEC", 0)), "rb") as file:
            if not stat.S_ISREG(os.fstat(file.fileno()).st_mode):
                return None
            while chunk := file.read(1 << 20):
                hashed.update(chunk)
    except OSError:
        return None
    return int.from_bytes(hashed.digest(), "big") // 2 + 1


def is_racy(state: FileState) -> bool:
    """Whether the stamp was taken within a tick of the file's last change."""
    return state is not None and state[4] != 0


def file_stamps(files: Iterable[str], read_ns: int | None = None) -> Stamps:
    """Each file with its :data:`FileState` (``read_ns``: when the caller began
    reading them, see :func:`stat_state`; None: read after, or compared): a
    long-running host (the language server, a validator plugin) compares them
    to read its configuration again when a file it read changed."""
    return tuple((path, file_state(path, read_ns=read_ns)) for path in files)


def stamps_hold(stamps: Stamps) -> bool:
    """Whether every file of ``stamps`` is as it was stamped (:func:`file_stamps`)."""
    return all(unchanged(path, held, file_state(path)) for path, held in stamps)


def unchanged(path: str, held: FileState, now: FileState) -> bool:
    """Whether the file at ``path``, stamped ``held`` then ``now``
    (:func:`file_state`), is as it was. A stamp that carries a digest (taken
    racy) still holds once the tick is over and the file's stamp has settled,
    the rest of it the same, while its bytes are: else a host read its
    configuration, or a layer, again only because the clock had moved on."""
    if now == held:
        return True
    return (
        held is not None
        and now is not None
        and held[4] > 0  # a digest (stat_state)
        and now[4] == 0
        and now[:4] == held[:4]
        and _digest(path) == held[4]
    )


def stamped_read(
    candidates: Sequence[str], read: Callable[[], _T], sources: Callable[[_T], Iterable[str]]
) -> tuple[_T, Stamps]:
    """``read()``'s result and the stamps of the files it read: ``candidates``,
    known before (:func:`config_candidates`, the file found among them), are
    stamped before it, so that a racy one is compared by its bytes; the other
    ``sources(result)`` (files it extends) after it, from when it began. Should
    one of those be racy, it is read once more with them stamped before too: a
    file dated ahead of the clock would else be read again on every look."""
    known = tuple(candidates)
    for _ in range(2):
        started = time.time_ns()
        before = file_stamps(known)
        result = read()
        seen = set(known)
        others = tuple(s for s in sources(result) if s not in seen)
        after = file_stamps(others, read_ns=started)
        if not any(is_racy(state) for _, state in after):
            break
        known = (*known, *others)
    return result, before + after


def config_candidates(path: str | Path) -> tuple[str, ...]:
    """Every file the search for ``path``'s configuration looks at (each
    configuration file name in its folder and every folder above): a
    long-running host stamps them with :func:`file_stamps` beside the files it
    read, so that one created later, nearer than the one in effect or where
    there was none, is read by its next lint (an editor or a host that watches
    no files says nothing). The user's own configuration's names too."""
    here = search_start(path)
    user = user_config_dir()
    folders = (here, *here.parents, *((user,) if user is not None else ()))
    return tuple(str(folder / name) for folder in folders for name in CONFIG_FILE_NAMES)


def search_start(start: str | Path) -> Path:
    """The folder the search for ``start``'s configuration begins in: its own
    resolved folder (a linked file's target's)."""
    # os.path.realpath, not Path.resolve: on Python < 3.13 the latter raises
    # RuntimeError for a symbolic link loop, which the file itself reports.
    here = Path(os.path.realpath(start))
    try:
        if here.is_file():
            here = here.parent
    except OSError:  # inside a folder without search permission: the file reports it
        here = here.parent
    return here


def config_file_in(folder: Path) -> Path | None:
    """The config file of ``folder`` itself (see :func:`find_config_file`)."""
    # A config file's name taken by something that is not a regular file (a
    # dangling link, a loop, a FIFO, a folder) is an error, not a file to skip
    # in favour of a parent folder's config.
    for name in CONFIG_FILE_NAMES[:-1]:
        dedicated = folder / name
        if os.path.lexists(dedicated):
            _read_config_bytes(dedicated)
            return dedicated
    pyproject = folder / "pyproject.toml"
    if os.path.lexists(pyproject) and _has_tool_table(pyproject):
        return pyproject
    return None


def _has_tool_table(pyproject: Path) -> bool:
    """Whether the file holds the table; one misspelt (``[tool.usdrender_lint]``) is
    an error, not a file without settings, whose defaults would pass silently."""
    tool = _load_toml(pyproject).get("tool", {})
    if not isinstance(tool, dict):
        return False
    if TOOL_TABLE not in tool:
        for name in tool:
            if _loose(name) == _loose(TOOL_TABLE):
                raise ConfigError(
                    f"{pyproject}: [tool.{name}] is not read: the table is [tool.{TOOL_TABLE}]"
                )
    return TOOL_TABLE in tool


def _loose(name: str) -> str:
    return re.sub(r"[-_.\s]", "", str(name)).lower()


def load_settings(
    config_path: str | None = None, *, isolated: bool = False, start: str = "."
) -> Settings:
    """Settings from ``--config``, else the nearest config file, else the
    user's own (:func:`user_config_file`), else defaults."""
    if isolated and config_path is not None:
        raise ConfigError("--config and --isolated cannot be used together")
    if isolated:
        return Settings()
    if config_path is not None:
        return read_config_file(config_path)
    found = find_config_file(start)
    return read_config_file(found) if found else fallback_settings()


def fallback_settings() -> Settings:
    """The settings of a file with no project configuration above it: the
    user's own configuration's (as ruff falls back to ``~/.config/ruff``),
    else the defaults."""
    user = user_config_file()
    return read_user_config(user) if user is not None else Settings()


# -- rule options -----------------------------------------------------------------


def build_options(options_class: type | None, values: Mapping[str, Any], where: str) -> Any:
    """Validate ``values`` against a rule's Options dataclass and build it."""
    if options_class is None:
        if values:
            raise ConfigError(f"{where}: this rule takes no options (got {', '.join(values)})")
        return None
    try:
        hints = typing.get_type_hints(options_class)
    except Exception as exc:  # noqa: BLE001 - a plugin's hint; said as its error, not ours
        raise ConfigError(
            f"{where}: the rule's Options type hints cannot be read "
            f"({type(exc).__name__}: {exc}); its plugin must define every name they use"
        ) from None
    fields = {f.name.replace("_", "-"): f.name for f in dataclasses.fields(options_class)}
    kwargs = {}
    for key, value in values.items():
        attr = fields.get(key) or (key if key in fields.values() else None)
        if attr is None:
            known = ", ".join(sorted(fields)) or "none"
            raise ConfigError(f"{where}: unknown option '{key}' (known: {known})")
        kwargs[attr] = _coerce(value, hints[attr], f"{where}.{key}")
    return options_class(**kwargs)


def _coerce(value: Any, hint: Any, where: str) -> Any:
    """``value`` as the rule option's type ``hint`` says (Literal, sequences,
    unions, Any, None, scalars); a ConfigError naming ``where`` otherwise."""
    origin = typing.get_origin(hint)
    if origin is typing.Literal:
        return _literal(value, typing.get_args(hint), where)
    if origin in (tuple, list, Sequence) or hint in (tuple, list):
        return _sequence(value, typing.get_args(hint), where)
    if origin in (set, frozenset, AbstractSet) or hint in (set, frozenset):
        # A TOML array; left a list, `options | {...}` failed inside the rule.
        return frozenset(_sequence(value, typing.get_args(hint), where))
    if origin in (dict, Mapping) or hint is dict:
        return _mapping(value, typing.get_args(hint), where)
    if origin in (typing.Union, types.UnionType):
        return _union(value, typing.get_args(hint), where)
    if isinstance(origin, type):
        # Another generic (an unchecked type let any value through): its class at least.
        return _scalar(value, origin, where)
    return _scalar(value, hint, where)


def _mapping(value: Any, args: tuple[Any, ...], where: str) -> dict[str, Any]:
    if not isinstance(value, Mapping):
        raise ConfigError(f"{where}: must be a table, got {value!r}")
    key_hint, item = args if len(args) == 2 else (Any, Any)
    return {
        _coerce(key, key_hint, where): _coerce(v, item, f"{where}.{key}")
        for key, v in value.items()
    }


def _literal(value: Any, allowed: tuple[Any, ...], where: str) -> Any:
    if value not in allowed:
        choices = ", ".join(repr(a) for a in allowed)
        raise ConfigError(f"{where}: must be one of {choices}, got {value!r}")
    return value


def _sequence(value: Any, args: tuple[Any, ...], where: str) -> tuple[Any, ...]:
    if not isinstance(value, (list, tuple)):
        raise ConfigError(f"{where}: must be a list, got {value!r}")
    item = args[0] if args else Any
    return tuple(_coerce(v, item, where) for v in value)


def _union(value: Any, options: tuple[Any, ...], where: str) -> Any:
    for option in options:
        try:
            return _coerce(value, option, where)
        except ConfigError:
            continue
    raise ConfigError(f"{where}: invalid value {value!r}")


def _scalar(value: Any, hint: Any, where: str) -> Any:
    if hint is Any:
        return value
    if hint is type(None):
        if value is not None:
            raise ConfigError(f"{where}: must be empty")
        return None
    if hint is float and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    if hint is bool and not isinstance(value, bool):
        raise ConfigError(f"{where}: must be true or false, got {value!r}")
    if (
        isinstance(hint, type)
        and not isinstance(value, hint)
        or (hint is int and isinstance(value, bool))
    ):
        raise ConfigError(f"{where}: must be {getattr(hint, '__name__', hint)}, got {value!r}")
    return value


__all__ = [
    "FAIL_ON_CHOICES",
    "MAX_JOBS",
    "MAX_TIMEOUT",
    "MAX_VARIANT_COMBINATIONS",
    "ConfigError",
    "Settings",
    "build_options",
    "find_config_file",
    "load_settings",
    "read_config_file",
]


# -- the configuration's JSON Schema ----------------------------------------------------


def json_schema() -> dict[str, Any]:
    """A JSON Schema of a ``.usdrender-lint.toml`` (the table
    ``[tool.usdrender-lint]`` of a ``pyproject.toml`` holds the same), derived
    from the settings table and the types of the Settings each key fills, as
    ruff derives its schema from its options: editors that read one (taplo,
    VS Code's Even Better TOML) complete and check the keys with it. Draft 4,
    the one taplo supports ("All features from the Draft 4 specification are
    supported": https://taplo.tamasfe.dev/configuration/developing-schemas.html).
    What a schema cannot say (which rule codes exist: plugins add them; a
    glob that names a folder) is checked when the file is read."""
    hints = typing.get_type_hints(Settings)
    properties: dict[str, Any] = {}
    for entry in SETTINGS:
        if not entry.config_key:
            continue
        schema = _schema_of(hints[entry.name])
        if entry.choices:
            schema = {"enum": list(entry.choices)}
        schema.update(entry.schema)
        schema["description"] = entry.help
        if entry.default is not None and not isinstance(entry.default, Mapping):
            default = entry.default
            schema["default"] = list(default) if isinstance(default, tuple) else default
        properties[entry.config_key] = schema
    return {
        "$schema": "http://json-schema.org/draft-04/schema#",
        "title": "usdrender-lint configuration",
        "type": "object",
        "properties": properties,
        "additionalProperties": False,
    }


def _schema_of(hint: Any) -> dict[str, Any]:
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (typing.Union, types.UnionType):
        return _schema_of(next(arg for arg in args if arg is not type(None)))
    if origin is tuple:
        # A list of strings; a single string is read as a list of one.
        return {"anyOf": [{"type": "array", "items": _schema_of(args[0])}, {"type": "string"}]}
    if origin is not None and issubclass(origin, Mapping):
        return {"type": "object", "additionalProperties": _schema_of(args[1])}
    if isinstance(hint, type) and issubclass(hint, Severity):
        # The names, for completion; any case and spaces around, as Severity.parse reads them.
        levels = [member.value for member in Severity]
        spelled = "|".join("".join(f"[{c}{c.upper()}]" for c in name) for name in levels)
        pattern = rf"^\s*({spelled})\s*$"
        return {"anyOf": [{"enum": levels}, {"type": "string", "pattern": pattern}]}
    if hint is Any:
        return {}
    types_of = {str: "string", bool: "boolean", int: "integer", float: "number"}
    return {"type": types_of[hint]}
