"""Every setting, declared once: its name, how a value is read and checked
(type and range), its default, its help, its configuration key, its flag and
whether it can change a finding (and so belongs in the result cache's key).

The configuration parser (:mod:`.config`), the command line's options
(:mod:`.cli.options`), the pipeline's :class:`~.running.pipeline.Request` and
the Python API's overrides are derived from :data:`SETTINGS`;
``tests/running/test_settings_table.py`` fails when a setting is missing from
any of them. No USD, click or rich here: ``--help`` reads it.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Mapping
from dataclasses import field
from typing import Any

from .model import PROFILE_NAMES, Severity
from .records import record

FAIL_ON_CHOICES = ("error", "warning", "info", "never")
#: The largest --timeout: a day per file (0 is no limit at all).
MAX_TIMEOUT = 86_400
#: The most worker processes a run starts.
MAX_JOBS = 1024
#: The most variant combinations linted per file (each composes the stage anew).
MAX_VARIANT_COMBINATIONS = 10_000
#: Folders never walked into unless named (beside every hidden file and folder):
#: other tools' environments, which hold USD files that are not the project's.
DEFAULT_EXCLUDE = ("node_modules", "site-packages", "venv", "__pypackages__")
#: Seconds one file may take by default: a hang (a FIFO in a layer stack, a
#: runaway composition) costs the file, not the run.
DEFAULT_TIMEOUT = 120.0


class ConfigError(Exception):
    """The configuration is invalid; the message names the key and the file."""


Parser = Callable[[Any, str], Any]


@record(frozen=True)
class Setting:
    """One setting. ``parse(value, where)`` checks a value from any source (a
    configuration file, a flag, the Python API) and returns it in the form the
    pipeline uses; it raises :class:`ConfigError` naming ``where``."""

    #: The name of the Settings field, the Request field and the API keyword.
    name: str
    help: str
    parse: Parser
    #: How the command line takes it: "tokens" (repeatable, comma-separated),
    #: "choice", "profile", "int", "float", "flag", "off-flag" (the flag turns
    #: the setting off), "folder"; None: configuration files only.
    kind: str | None = None
    default: Any = None
    #: The key in ``[tool.usdrender-lint]``; None: not a configuration key.
    config_key: str | None = None
    #: The command-line flag; None: no flag.
    flag: str | None = None
    #: A one-letter form of the flag ("-j").
    short: str | None = None
    #: The commands that take the flag.
    commands: tuple[str, ...] = ("check",)
    #: Shown after the help as "[default: ...]" when it is not the default's repr.
    shown_default: str | None = None
    #: An environment variable the flag reads (click's ``envvar``).
    envvar: str | None = None
    #: A keyword of the Python API (``lint_file``).
    api: bool = False
    #: Whether the value can change a finding (it is in the result cache's key).
    changes_findings: bool = True
    choices: tuple[str, ...] = ()
    hidden: bool = False
    #: A "flag" that also has its ``--no-`` form (to undo what a configuration
    #: or a hook's arguments turned on).
    negatable: bool = False
    #: How a file that ``extend``s another combines its value with that file's:
    #: "replaced"; "merged" (a table, entry by entry; a rule's options option by
    #: option); "added" (a list: the extended file's entries, then its own).
    extended: str = "replaced"
    #: What the JSON Schema says of a value beyond its type, as ``parse`` checks
    #: it (a number's range, a path that is not blank): config.json_schema.
    schema: Mapping[str, Any] = field(default_factory=dict)


# -- parsers --------------------------------------------------------------------------


def _key(where: str, key: str) -> str:
    """``where`` of a sub-key: "file: 'severity'" -> "file: 'severity.SE003'"."""
    return f"{where[:-1]}.{key}'" if where.endswith("'") else f"{where}.{key}"


def _strings(value: Any, where: str) -> tuple[str, ...]:
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list | tuple) or not all(isinstance(v, str) for v in value):
        raise ConfigError(f"{where} must be a list of strings, got {value!r}")
    return tuple(value)


def _patterns(value: Any, where: str) -> tuple[str, ...]:
    """Gitignore-style patterns: one that git's reading refuses (a lone ``!``,
    a trailing backslash) is an error here, not in the middle of a walk."""
    patterns = _strings(value, where)
    for pattern in patterns:
        if "!" in pattern or "\\" in pattern:  # what makes a pattern invalid
            from pathspec import GitIgnoreSpec  # only for such a pattern

            try:
                GitIgnoreSpec.from_lines([pattern])
            except ValueError:
                raise ConfigError(
                    f"{where}: {pattern!r} is not a gitignore-style pattern (a lone '!' or "
                    "a trailing backslash matches nothing)"
                ) from None
    return patterns


def _tokens(value: Any, where: str) -> tuple[str, ...]:
    """Rule codes, prefixes or names: ``["A,B", "C"]`` -> ("A", "B", "C"). A
    blank entry names no rule (``select = [""]`` ran none, silently), as ruff
    refuses a selector it cannot read."""
    items = _strings(value, where)
    if any(not item.strip(" ,\t") for item in items):
        raise ConfigError(f"{where} has a blank entry, which names no rule, got {list(items)!r}")
    return tuple(v.strip() for item in items for v in item.split(",") if v.strip())


def _table(value: Any, where: str, shape: str) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise ConfigError(f"{where} must be a table of {shape}, got {value!r}")
    return value


def _fail_on(value: Any, where: str) -> str:
    if value not in FAIL_ON_CHOICES:
        raise ConfigError(f"{where} must be one of {', '.join(FAIL_ON_CHOICES)}, got {value!r}")
    return value


def _severities(value: Any, where: str) -> dict[str, Severity]:
    overrides = {}
    for rule, level in _table(value, where, "rule = severity").items():
        try:
            overrides[rule] = Severity.parse(level if isinstance(level, str) else "")
        except ValueError:
            raise ConfigError(
                f"{_key(where, rule)} must be one of error, warning, info, got {level!r}"
            ) from None
    return overrides


def _glob(glob: str, where: str) -> str:
    """A file glob of a table: one blank once its leading ``!`` is read (``""``,
    spaces, ``{,}``) or naming a folder (``legacy/``) matches no file, and its
    negation every file, silently.
    ruff refuses a glob it cannot compile (crates/ruff_linter/src/settings/types.rs,
    ``Glob::new(...)?``); a blank one compiles there but names no file either."""
    rest = glob[1:] if glob.startswith("!") else glob
    if not re.sub(r"[\s{},]", "", rest):
        if glob.startswith("!"):
            why = "negates an empty glob, so it matches every file"
        else:
            why = "is an empty glob, which matches no file"
        raise ConfigError(f'{_key(where, glob)} {why}: name the files, e.g. "shots/**/*.usda"')
    if rest.rstrip().endswith("/"):
        # A folder, as in .gitignore and `exclude`: here a glob names files, so
        # it matched none (negated, every file), as ruff's per-file-ignores do.
        folder, negated = rest.rstrip().rstrip("/"), glob.startswith("!")
        matches = "every file" if negated else "no file"
        meant = (
            f'"!{folder}/**" matches every file outside it'
            if negated
            else (f'"{folder}/**" matches every file below it')
        )
        raise ConfigError(
            f"{_key(where, glob)} names a folder, and these globs match files, so it matches "
            f"{matches}: {meant}"
        )
    return glob


#: A JSON Schema pattern of a glob :func:`_glob` reads: a character other than
#: spaces, braces and commas, after a leading ``!`` (no look-ahead: taplo's regex has none).
GLOB_NOT_BLANK = r"^(!.*[^\s{},]|[^!\s{},]|[\s{},].*[^\s{},])"


def _glob_tokens(value: Any, where: str) -> dict[str, tuple[str, ...]]:
    table = _table(value, where, "glob = codes")
    return {_glob(glob, where): _strings(codes, _key(where, glob)) for glob, codes in table.items()}


def _rule_tables(value: Any, where: str) -> Mapping[str, Mapping[str, Any]]:
    for rule, options in _table(value, where, "rule tables").items():
        _table(options, _key(where, rule), "option = value")
    return value


def _whole(low: int, high: int | None) -> Parser:
    """Whole numbers from ``low`` (1) to ``high`` (None: no bound)."""

    def parse(value: Any, where: str) -> int:
        if (
            isinstance(value, bool)
            or not isinstance(value, int)
            or value < low
            or (high is not None and value > high)
        ):
            kind = f"a whole number from {low} to {high}" if high else "a positive integer"
            raise ConfigError(f"{where} must be {kind}, got {value!r}")
        return value

    return parse


def _seconds(value: Any, where: str) -> float:
    """0 (no limit) to MAX_TIMEOUT; NaN and infinities are not seconds."""
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not 0 <= value <= MAX_TIMEOUT
    ):
        raise ConfigError(
            f"{where} must be a number of seconds from 0 to {MAX_TIMEOUT} (0: no limit), "
            f"got {value!r}"
        )
    return float(value)


def _bool(value: Any, where: str) -> bool:
    if not isinstance(value, bool):
        raise ConfigError(f"{where} must be true or false, got {value!r}")
    return value


def _profile(value: Any, where: str) -> str:
    """A profile name; which names exist is checked where the profiles are
    known (running.pipeline.check_profiles)."""
    if not isinstance(value, str) or not value:
        raise ConfigError(f"{where} must be a profile name, got {value!r}")
    return value


def _glob_profiles(value: Any, where: str) -> dict[str, str]:
    table = _table(value, where, "glob = profile")
    return {_glob(glob, where): _profile(name, _key(where, glob)) for glob, name in table.items()}


def _file(value: Any, where: str) -> str:
    if not isinstance(value, str) or not value.strip():
        raise ConfigError(f"{where} must be the path of a configuration file, got {value!r}")
    return expand_path(value, where)


def _folder(value: Any, where: str) -> str:
    if not isinstance(value, str) or not value.strip():
        raise ConfigError(f"{where} must be a folder path, got {value!r}")
    return expand_path(value, where)


#: A variable of a path: $NAME or ${NAME}.
_VARIABLE = r"\$(?:(\w+)|\{(\w+)\})"  # compiled when first used, not at start-up


def expand_path(value: str, where: str) -> str:
    """``value`` with ``~`` and environment variables expanded, as ruff expands
    its ``cache-dir`` and ``extend`` (https://docs.astral.sh/ruff/settings/#extend):
    ``~/.cache/x`` is no folder named ``~`` in the project. A variable that is
    not set is an error, not a folder named ``$STUDIO``."""
    for found in re.finditer(_VARIABLE, value) if "$" in value else ():
        name = found.group(1) or found.group(2)
        if name not in os.environ:
            raise ConfigError(f"{where}: environment variable {name} is not set (in {value!r})")
    return os.path.expandvars(os.path.expanduser(value))


#: A JSON Schema pattern of a string that is not empty nor only spaces.
NOT_BLANK = r"\S"

# -- the table ------------------------------------------------------------------------

SETTINGS: tuple[Setting, ...] = (
    Setting(
        "extend",
        "Another configuration file whose settings this one starts from (relative to this "
        "file's folder; ~ and $VARIABLES expand): a show's settings on top of a studio's.",
        _file,
        config_key="extend",
        schema={"pattern": NOT_BLANK},
        changes_findings=False,
    ),
    Setting(
        "select",
        "Rules to run: codes, prefixes (CA) or names.",
        _tokens,
        kind="tokens",
        config_key="select",
        flag="--select",
        commands=("check", "rules"),
        api=True,
    ),
    Setting(
        "ignore",
        "Rules to skip: codes, prefixes or names.",
        _tokens,
        kind="tokens",
        default=(),
        config_key="ignore",
        flag="--ignore",
        commands=("check", "rules"),
        api=True,
    ),
    Setting(
        "extend_select",
        "Rules to add to the selection.",
        _tokens,
        kind="tokens",
        default=(),
        config_key="extend-select",
        flag="--extend-select",
        commands=("check", "rules"),
        api=True,
    ),
    Setting(
        "fail_on",
        "Lowest severity that makes the exit code 1",
        _fail_on,
        kind="choice",
        default="error",
        config_key="fail-on",
        flag="--fail-on",
        commands=("check", "merge"),
        shown_default="error",
        choices=FAIL_ON_CHOICES,
        changes_findings=False,
    ),
    Setting(
        "severity",
        "Severity overrides, keyed by rule code or name.",
        _severities,
        default={},
        config_key="severity",
        api=False,
        extended="merged",
    ),
    Setting(
        "per_path_ignores",
        "File glob -> codes, prefixes or names ignored in matching files.",
        _glob_tokens,
        # Each key a glob that names some file (_glob); the values as _schema_of writes them.
        schema={
            "patternProperties": {
                GLOB_NOT_BLANK: {
                    "anyOf": [{"type": "array", "items": {"type": "string"}}, {"type": "string"}]
                }
            },
            "additionalProperties": False,
        },
        default={},
        config_key="per-path-ignores",
        extended="merged",
    ),
    Setting(
        "rule_options",
        "Rule name or code -> option values, validated against the rule's Options.",
        _rule_tables,
        default={},
        config_key="rules",
        extended="merged",
    ),
    Setting(
        "roots",
        "Globs of stage root files (changed layers are linted in their roots).",
        _strings,
        default=(),
        config_key="roots",
    ),
    Setting(
        "time_sample_cap",
        "Cap on authored time samples evaluated per attribute.",
        _whole(1, None),
        default=1000,
        config_key="time-sample-cap",
        schema={"minimum": 1},
    ),
    Setting(
        "unfixable",
        "Rules (codes, prefixes or names) whose fixes --fix never applies.",
        _tokens,
        default=(),
        config_key="unfixable",
        changes_findings=False,
        # As ruff's: a file extending another cannot make its unfixable rules fixable.
        extended="added",
    ),
    Setting(
        "variants",
        "Also lint under other variant selections of the render prims and their ancestors.",
        _bool,
        kind="flag",
        default=False,
        config_key="variants",
        flag="--variants",
        api=True,
    ),
    Setting(
        "max_variant_combinations",
        "With --variants: variant combinations linted per file at most",
        _whole(1, MAX_VARIANT_COMBINATIONS),
        schema={"minimum": 1, "maximum": MAX_VARIANT_COMBINATIONS},
        kind="int",
        default=64,
        config_key="max-variant-combinations",
        flag="--max-variant-combinations",
        shown_default="64",
        api=True,
    ),
    Setting(
        "profile",
        "Renderer profile: auto (inferred per RenderSettings) or a name",
        _profile,
        # The names, for `config profile` and an editor's completion (check_profiles reads them).
        schema={"enum": ["auto", *PROFILE_NAMES]},
        kind="profile",
        default="auto",
        config_key="profile",
        flag="--profile",
        commands=("check", "spec"),
        shown_default="auto",
        api=True,
    ),
    Setting(
        "per_path_profiles",
        "File glob -> profile name for matching files (wins over profile).",
        _glob_profiles,
        schema={
            "patternProperties": {GLOB_NOT_BLANK: {"enum": ["auto", *PROFILE_NAMES]}},
            "additionalProperties": False,
        },
        default={},
        config_key="per-path-profiles",
        extended="merged",
    ),
    # Which files a folder yields (running/discovery.py): never what is found in a file.
    Setting(
        "exclude",
        "Gitignore-style patterns of files and folders not linted when a folder is walked "
        "(a path given is linted unless --force-exclude); replaces the default list",
        _patterns,
        kind="tokens",
        default=DEFAULT_EXCLUDE,
        config_key="exclude",
        flag="--exclude",
        commands=("check", "spec"),
        shown_default=", ".join(DEFAULT_EXCLUDE),
        changes_findings=False,
    ),
    Setting(
        "extend_exclude",
        "Patterns excluded as well as --exclude's (added to the configuration's extend-exclude)",
        _patterns,
        kind="tokens",
        default=(),
        config_key="extend-exclude",
        flag="--extend-exclude",
        commands=("check", "spec"),
        changes_findings=False,
        extended="added",
    ),
    Setting(
        "respect_gitignore",
        "Skip what .gitignore files (and .git/info/exclude) ignore when a folder is walked.",
        _bool,
        default=True,
        config_key="respect-gitignore",
        changes_findings=False,
    ),
    Setting(
        "force_exclude",
        "Skip a path given too where a folder walk would skip it (hidden, exclude, "
        ".gitignore): a pre-commit hook names every staged file.",
        _bool,
        kind="flag",
        default=False,
        config_key="force-exclude",
        flag="--force-exclude",
        commands=("check", "spec"),
        changes_findings=False,
        negatable=True,
    ),
    Setting(
        "cache_dir",
        "The result cache's folder (~ and $VARIABLES expand)",
        _folder,
        schema={"pattern": NOT_BLANK},
        kind="folder",
        config_key="cache-dir",
        flag="--cache-dir",
        shown_default=".usdrender_lint_cache at the project root",
        envvar="USDRENDER_LINT_CACHE_DIR",
        commands=("check", "clean"),
        changes_findings=False,
    ),
    # Run options: how files are linted, never what is found.
    Setting(
        "jobs",
        "Files linted in parallel worker processes",
        _whole(1, MAX_JOBS),
        kind="int",
        flag="--jobs",
        short="-j",
        commands=("check", "spec"),
        shown_default="the CPU count",
        changes_findings=False,
    ),
    Setting(
        "timeout",
        "Seconds one file may take before it is reported as an error; 0: no limit.",
        _seconds,
        kind="float",
        default=DEFAULT_TIMEOUT,
        flag="--timeout",
        commands=("check", "spec"),
        changes_findings=False,
    ),
    Setting(
        "cache",
        "Lint every file, neither reading nor writing the result cache.",
        _bool,
        kind="off-flag",
        default=True,
        flag="--no-cache",
        envvar="USDRENDER_LINT_NO_CACHE",
        changes_findings=False,
    ),
    Setting(
        "full_composition",
        "Compose every stage in full, not only what the rules read (same findings, slower).",
        _bool,
        kind="flag",
        default=False,
        flag="--full-composition",
        hidden=True,
        changes_findings=False,
    ),
)

BY_NAME: Mapping[str, Setting] = {s.name: s for s in SETTINGS}
BY_CONFIG_KEY: Mapping[str, Setting] = {s.config_key: s for s in SETTINGS if s.config_key}


def setting(name: str) -> Setting:
    return BY_NAME[name]


def flag_settings(command: str) -> tuple[Setting, ...]:
    """The settings ``command`` takes as flags, in the table's order."""
    return tuple(s for s in SETTINGS if s.flag and command in s.commands)


def request_settings() -> tuple[Setting, ...]:
    """The settings a Request carries: every one a flag or the API can give."""
    return tuple(s for s in SETTINGS if s.flag or s.api)


def check_value(name: str, value: Any, where: str | None = None) -> Any:
    """``value`` checked as setting ``name`` (where: its flag by default)."""
    entry = BY_NAME[name]
    return entry.parse(value, where or entry.flag or name)


def settings_key(settings: object) -> dict[str, Any]:
    """The values of a Settings that can change a finding (the result cache's
    key and merge's configuration digest hold them)."""
    key = {
        s.name: getattr(settings, s.name) for s in SETTINGS if s.config_key and s.changes_findings
    }
    below = getattr(settings, "selections_below", ())
    if below:  # the layers beneath choose rules too; where they came from does not matter
        key["selections_below"] = [(b.select, b.ignore, b.extend_select) for b in below]
    return key


def not_in_cache_key() -> frozenset[str]:
    """The settings that cannot change a finding."""
    return frozenset(s.name for s in SETTINGS if not s.changes_findings)
