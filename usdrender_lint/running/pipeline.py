"""The one check pipeline: a :class:`Request` goes in, an :class:`Outcome` comes out.

The command line only parses its options into a Request and prints the
Outcome; the Python API (:mod:`.python_api`) builds the same Request. Every
step lives here once: configuration, rule selection and options, file
discovery, roots, fixing, the workers, per-path ignores and the baseline, and
the exit status. Nothing here imports click or rich.
"""

from __future__ import annotations

import os
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import replace
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from ..api import Rule
from ..config import (
    SELECTION_KEYS,
    ConfigError,
    Settings,
    build_options,
    config_file_in,
    fallback_settings,
    load_settings,
    read_config_file,
    reading_once,
    with_inline,
    with_key_line,
)
from ..engine import Linter, SchemasMissing, plugin_notes
from ..model import FileResult, Finding, Report, Severity
from ..profiles import AUTO, PROFILES
from ..profiles.detect import Profiler
from ..records import record
from ..registry import Registry, SelectionError, build_registry, matches_any, select_rules
from ..settings_table import DEFAULT_TIMEOUT, request_settings
from .discovery import Exclusions, FolderExclusions, collect_files, force_excluded, walk_skips
from .hierarchy import configuration_groups, given_files
from .path_ignores import UNIGNORABLE, apply_path_ignores
from .supervisor import Supervision
from .workers import (
    ExecutionError,
    FileLinter,
    LinterFactory,
    Pool,
    default_jobs,
    lint_paths,
)

if TYPE_CHECKING:
    from ..engine.variants import VariantExplorer
    from ..fixing import FixOptions, FixRun
    from .result_cache import CachingLinter, ResultCache
    from .roots import ContextPlan

EXIT_OK, EXIT_FINDINGS, EXIT_TOOL_ERROR = 0, 1, 2


class RequestError(Exception):
    """The request cannot be carried out at all (a usage or configuration
    error, a rule plugin that fails to load): one line, exit 2."""


class SchemasRefused(RequestError):
    """Nothing can be linted: this process's USD schema registry lacks the
    rules' schemas (engine.SchemasMissing). The Python API, which lints in
    this process, raises its own error for it, not a configuration error."""


@record(frozen=True)
class FixRequest:
    """What fixing was asked for: ``--fix``, ``--diff`` or ``--fix-to LAYER``."""

    #: False for --diff: compute the edits, report them, write nothing.
    write: bool = True
    unsafe: bool = False
    #: Write every fix as an override into this layer (--fix-to).
    fix_to: str | None = None


class TextLayer(Protocol):
    """``check -``: a layer's text linted in place of a file; the pipeline does the
    rest as for a file (running/standard_input.py, above the pipeline, lints it)."""

    @property
    def name(self) -> str:
        """The path the text stands for, as given: its name in the report."""
        ...

    @property
    def text(self) -> str: ...

    def lint(self, prepared: Prepared) -> FileResult: ...

    def fix(self, prepared: Prepared) -> tuple[FixRun, TextLayer]:
        """The request's fixes of the text: what was done, and the text left."""
        ...


@record(frozen=True)
class Request:
    """Everything a check run needs, as the user asked for it. ``None`` means
    "not given": the configuration (or its default) decides."""

    paths: tuple[str, ...]
    select: tuple[str, ...] | None = None
    ignore: tuple[str, ...] | None = None
    extend_select: tuple[str, ...] | None = None
    fail_on: str | None = None
    #: A Settings object, a config file path, or None to search from the first path.
    config: Settings | str | os.PathLike[str] | None = None
    #: Inline settings (``--config 'KEY = VALUE'``, or the editor's table), laid over
    #: the configuration in order, under the flags.
    config_overrides: tuple[str | Mapping[str, Any], ...] = ()
    #: Ignore every configuration file (the defaults and the flags only).
    isolated: bool = False
    #: Lint the paths on their own even when the config sets ``roots``.
    use_roots: bool = True
    fix: FixRequest | None = None
    variants: bool | None = None
    max_variant_combinations: int | None = None
    baseline: str | None = None
    write_baseline: str | None = None
    jobs: int | None = None
    timeout: float | None = DEFAULT_TIMEOUT
    #: None: a progress bar on a terminal for long runs.
    progress: bool | None = None
    #: Compose every stage in full (no fast path; same findings, slower).
    full_composition: bool = False
    #: The renderer profile (--profile): "auto" or a name; None: the config's.
    profile: str | None = None
    #: Reuse and store results in the result cache (running/result_cache.py);
    #: the command line's default, off for the Python API.
    cache: bool = False
    #: Where the cache lives; None: config ``cache-dir``, else the project root.
    cache_dir: str | os.PathLike[str] | None = None
    #: (K, N): lint only part K of N of the files (running/shards.py).
    shard: tuple[int, int] | None = None
    #: How the supervisor ran this process (running/supervisor.py); None: not supervised.
    supervision: Supervision | None = None
    #: Patterns not linted in a folder walked (--exclude, --extend-exclude).
    exclude: tuple[str, ...] | None = None
    extend_exclude: tuple[str, ...] | None = None
    #: Skip a path given too where a walk would (--force-exclude); None: the config's.
    force_exclude: bool | None = None
    #: The file the caller will write the report to (--output): refused, before
    #: anything is linted, when the run reads it (running/outputs.py).
    output: str | None = None
    #: ``check -``: the one layer linted, a text read from standard input; its name
    #: is ``paths``' one entry.
    stdin: TextLayer | None = None


@record(frozen=True)
class Outcome:
    """What a check run produced. ``notes`` are lines for the user beside the
    report (stderr on the command line); ``errors`` are the files the tool
    could not lint, one line each."""

    report: Report
    settings: Settings
    rules: tuple[Rule, ...]
    exit_status: int
    #: With --diff: one unified diff per changed text layer (a patch).
    diffs: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    #: Layers fixing could not write, one line each (the run exits 2).
    fix_errors: tuple[str, ...] = ()
    #: The baseline's finding counts the run read (None: no baseline).
    baseline: Counter | None = None
    #: How many findings the baseline hid (the note that says so is in ``notes``).
    baseline_dropped: int = 0
    #: How many findings the baseline records that the files linted no longer have.
    baseline_stale: int = 0
    #: ``check --fix -``: the fixed text, the command's output (nothing is written).
    text: str | None = None
    #: A run split by configuration (running/hierarchy.py): each one's outcome.
    parts: tuple[Outcome, ...] = ()

    def settings_by_file(self) -> dict[str, Settings]:
        """The configuration each file of the report was linted with."""
        return {r.file: o.settings for o in self.parts or (self,) for r in o.report.files}

    def configuration(self) -> str:
        """The run's configuration digest, which merge compares (running/merge.py).
        Computed when asked for: only a report that records it needs it, and
        its hashing and JSON imports cost more than a small file's lint."""
        from .merge import configuration_digest, digest_of_parts

        if self.parts:
            return digest_of_parts([part.configuration() for part in self.parts])
        return configuration_digest(self.settings, self.rules, self.baseline)

    @property
    def fails_on_info(self) -> bool:
        """Whether an info finding fails the run (then the text report shows them)."""
        return any(o.settings.fail_on == "info" for o in self.parts or (self,))

    @property
    def errors(self) -> tuple[str, ...]:
        return tuple(r.error or r.file for r in self.report.errored_files) + self.fix_errors


# -- configuration to a linter ----------------------------------------------------


def resolve_settings(request: Request) -> Settings:
    """The configuration the request names or finds, with its flags applied."""
    if request.isolated and request.config is not None:
        raise ConfigError("--config and --isolated cannot be used together")
    if isinstance(request.config, Settings):
        settings = request.config
    elif request.config is not None:
        settings = read_config_file(request.config)
    else:
        start = request.paths[0] if request.paths else "."
        settings = load_settings(isolated=request.isolated, start=start)
    settings = with_inline(settings, request.config_overrides)
    # Every configuration key the request can give (a flag or an API keyword) wins.
    return settings.merged(
        **{s.name: getattr(request, s.name) for s in request_settings() if s.config_key}
    )


def check_request(request: Request) -> None:
    """Raise a ConfigError for an option value out of range, or for relative
    paths that cannot be reached from the working directory."""
    if request.write_baseline and request.shard is not None:
        # A part's findings alone: every other part's would read as new.
        raise ConfigError(
            "--write-baseline records every finding of a check: run it without --shard"
        )
    if request.write_baseline and request.fix is not None and not request.fix.write:
        # Two answers for one exit code: "written" (0) and "a fix is pending" (1).
        raise ConfigError(
            "use either --diff or --write-baseline, not both: --diff exits 1 when a fix is "
            "pending, --write-baseline exits 0 once written"
        )
    named = [*request.paths]
    if isinstance(request.config, str | os.PathLike):
        named.append(os.fspath(request.config))
    if any(not os.path.isabs(path) for path in named):
        check_working_directory()
    for entry in request_settings():
        value = getattr(request, entry.name)
        if value is not None:
            entry.parse(value, entry.flag or entry.name)


def path_max() -> int:
    try:
        return os.pathconf("/", "PC_PATH_MAX")
    except (OSError, ValueError, AttributeError):
        return 4096


def check_working_directory() -> None:
    """A working directory that is gone, or whose path is longer than
    PATH_MAX: no file below it can be opened by its absolute path, which is
    how USD opens every layer, so stop with one line instead of failing on
    every file (or in the configuration search)."""
    try:
        cwd = os.getcwd()
    except OSError as exc:
        raise ConfigError(
            f"the working directory cannot be read ({exc.strerror}); change to another "
            "folder or give absolute paths"
        ) from None
    limit = path_max()
    if len(os.fsencode(cwd)) >= limit:
        raise ConfigError(
            f"the working directory's path is {len(os.fsencode(cwd)):,} bytes long, more than "
            f"PATH_MAX ({limit:,}): USD cannot open files below it; change to a folder with a "
            "shorter path"
        )


def make_rules(registry: Registry, settings: Settings) -> list[Rule]:
    """Instantiate the selected rules with their validated options."""
    for token in settings.unfixable:
        check_selectors(registry, [token], settings.where_entry("unfixable", token))
    for layer in settings.selection_layers:
        for key in SELECTION_KEYS:
            check_selectors(registry, getattr(layer, key) or (), layer.origins[key])
    unignorable_notes(registry, settings)
    for glob, selectors in settings.per_path_ignores.items():
        where = f"{settings.where_entry('per_path_ignores', glob)}.{glob}"
        check_selectors(registry, selectors, where)
        for rule, token in _unignorable_named(registry, selectors):
            # A wider selector (ALL, ST) ignores the others: path_ignores keeps it.
            raise ConfigError(f"{where}: {token!r} cannot be ignored: {_always_reported(rule)}")
    for key, severity in settings.severity.items():
        lowered = registry.find(key)
        if lowered is not None and lowered.code in UNIGNORABLE and severity is not Severity.ERROR:
            raise ConfigError(
                f"{settings.where_entry('severity', key)}.{key}: {lowered.code} is always an "
                f"error: {_always_reported(lowered)}"
            )
    try:
        *below, own = settings.selection_layers
        chosen = select_rules(
            registry.rules,
            own.select,
            own.ignore,
            own.extend_select,
            [(layer.select, layer.ignore, layer.extend_select) for layer in below],
        )
    except SelectionError as exc:
        raise ConfigError(str(exc)) from None
    options = _options_by_code(registry, settings)
    return [rule(options.get(rule.code)) for rule in chosen]


def unignorable_notes(registry: Registry, settings: Settings) -> list[str]:
    """Raise a ConfigError for an ``ignore`` that names an unignorable rule
    itself (``--ignore ST001``); one note for each wider selector that covers
    one (``--ignore ALL``, ``--ignore ST``), which ignores the others."""
    # The last layer's first: a flag is named before the file beneath it.
    ignores = [(layer.origins["ignore"], layer.ignore) for layer in settings.selection_layers]
    ignores.reverse()
    for where, ignore in ignores:
        for rule, token in _unignorable_named(registry, ignore):
            raise ConfigError(f"{where}: {token!r} cannot be ignored: {_always_reported(rule)}")
    return [
        f"note: ignore {token!r}: {_always_reported(rule, fix=False)}; the other rules it "
        "names are ignored"
        for rule in registry.rules
        if rule.code in UNIGNORABLE
        for _, ignore in ignores
        for token in ignore
        if matches_any(rule, [token])
    ]


def _unignorable_named(
    registry: Registry, selectors: Iterable[str]
) -> Iterator[tuple[type[Rule], str]]:
    """Each unignorable rule a selector names itself (its code or its name)."""
    for rule in registry.rules:
        if rule.code in UNIGNORABLE:
            for token in selectors:
                if token.strip().upper() == rule.code or token.strip().lower() == rule.name:
                    yield rule, token


def _always_reported(rule: type[Rule], fix: bool = True) -> str:
    why = (
        f"{rule.code} ({rule.name}) is always reported: a file USD cannot open is not "
        "linted, and a gate must not pass it"
    )
    return why + ("; fix the file, or leave it out of the paths linted" if fix else "")


def check_selectors(registry: Registry, selectors: Iterable[str], where: str) -> None:
    """Raise a ConfigError naming ``where`` for a selector that names no rule."""
    for token in selectors:
        if not any(matches_any(rule, [token]) for rule in registry.rules):
            near = registry.nearest(token)
            hint = f" (did you mean {near!r}?)" if near else ""
            raise ConfigError(
                f"{where}: {token!r} matches no rule code, code prefix or rule name{hint}"
            )


def _options_by_code(registry: Registry, settings: Settings) -> dict[str, object]:
    """Each rule's options. Tables naming one rule by its code and by its name
    (a studio's [rules.lpe-malformed] under a show's [rules.VA003]) merge option
    by option, the later winning, as one table extended does."""
    merged: dict[str, tuple[type[Rule], dict[str, Any], str]] = {}
    for key, values in settings.rule_options.items():
        rule = registry.find(key)
        where = f"{settings.where_entry('rule_options', key)}.{key}"
        if rule is None:
            raise ConfigError(f"{where}: no rule has this code or name")
        build_options(rule.Options, values, where)  # each table's errors name it
        _, options, _ = merged.get(rule.code, (rule, {}, where))
        options.update({name.replace("_", "-"): value for name, value in values.items()})
        merged[rule.code] = (rule, options, where)
    return {
        code: build_options(rule.Options, options, where)
        for code, (rule, options, where) in merged.items()
    }


def severity_overrides(registry: Registry, settings: Settings) -> dict[str, Severity]:
    overrides = {}
    for key, severity in settings.severity.items():
        rule = registry.find(key)
        if rule is None:
            raise ConfigError(
                f"{settings.where_entry('severity', key)}.{key}: no rule has this code or name"
            )
        overrides[rule.code] = severity
    return overrides


def make_linter(
    settings: Settings, registry: Registry | None = None, *, full_composition: bool = False
) -> Linter:
    registry = registry or build_registry()
    check_profiles(settings)
    return Linter(
        make_rules(registry, settings),
        severity_overrides(registry, settings),
        time_sample_cap=settings.time_sample_cap,
        known_rules=registry.rules,
        full_composition=full_composition,
        profiler=Profiler(profile_chooser(settings)),
    )


def check_profiles(settings: Settings) -> None:
    """Raise a ConfigError naming the key for a profile that does not exist."""
    known = [AUTO, *PROFILES]
    named = [(settings.profile, settings.where("profile"))]
    named += [
        (name, f"{settings.where_entry('per_path_profiles', glob)}.{glob}")
        for glob, name in settings.per_path_profiles.items()
    ]
    for name, where in named:
        if name not in known:
            raise ConfigError(f"{where}: unknown profile {name!r} (known: {', '.join(known)})")


def profile_chooser(settings: Settings):
    """The configured profile of a file, and where it was configured: the
    command line's --profile, else the first per-path-profiles glob that
    matches (a nearer layer's first: ``Settings.nearest_first``), else the
    config's ``profile`` (default auto)."""
    from .path_ignores import matches_path

    base_dir = settings.base_dir

    def choose(file: str) -> tuple[str, str]:
        if "profile" in settings.from_flags:
            return settings.profile, f"--profile {settings.profile}"
        for glob, name in settings.nearest_first("per_path_profiles"):
            if matches_path(glob, file, base_dir):
                return name, f"{settings.where_entry('per_path_profiles', glob)}.{glob} = {name}"
        if settings.profile != "auto":
            return settings.profile, f"{settings.where('profile')} = {settings.profile}"
        return settings.profile, ""

    return choose


def profile_choice_key(settings: Settings) -> list[object]:
    """What :func:`profile_chooser`'s answers depend on besides the settings'
    values (which the result cache's key holds): whether --profile was given
    (it wins over per-path-profiles), the files that set the profile settings
    (each finding's profile reason names them), the folder the
    per-path-profiles globs are read from and the order they are tried in."""
    return [
        "profile" in settings.from_flags,
        settings.where("profile"),
        settings.where("per_path_profiles"),
        str(settings.base_dir) if settings.per_path_profiles else None,
        [
            (glob, settings.where_entry("per_path_profiles", glob))
            for glob, _ in settings.nearest_first("per_path_profiles")
        ],
    ]


@record(frozen=True)
class LinterSpec:
    """A picklable recipe for the linter: worker processes build theirs from it,
    so every process lints with the same rules, options and composition."""

    settings: Settings
    full_composition: bool = False
    #: With --variants: the variant combinations linted per file at most.
    variant_combinations: int | None = None
    #: Store each result linted in this cache.
    cache: ResultCache | None = None

    def __call__(self) -> Linter | VariantExplorer | CachingLinter:
        return self.wrap(make_linter(self.settings, full_composition=self.full_composition))

    def wrap(self, linter: Linter) -> Linter | VariantExplorer | CachingLinter:
        wrapped: Linter | VariantExplorer = linter
        if self.variant_combinations is not None:
            from ..engine.variants import VariantExplorer

            wrapped = VariantExplorer(linter, self.variant_combinations)
        if self.cache is None:
            return wrapped
        from .result_cache import CachingLinter

        return CachingLinter(wrapped, self.cache)


@record(frozen=True)
class LintersByFile:
    """A picklable recipe for linting the files of several configurations in one
    set of workers: each worker builds a configuration's linter from its spec the
    first time one of its files comes."""

    specs: tuple[LinterSpec, ...]
    #: Each file's index into ``specs``.
    part_of: Mapping[str, int]

    def __call__(self) -> _LintersOfFiles:
        return _LintersOfFiles(self)


class _LintersOfFiles:
    def __init__(self, recipe: LintersByFile) -> None:
        self.recipe = recipe
        self.built: dict[int, Linter | VariantExplorer | CachingLinter] = {}

    def lint_path(self, path: str, *, full_composition: bool = False) -> FileResult:
        index = self.recipe.part_of[path]
        if index not in self.built:
            self.built[index] = self.recipe.specs[index]()
        return self.built[index].lint_path(path, full_composition=full_composition)


@record
class Prepared:
    """The request turned into what runs: settings, registry, linter."""

    request: Request
    settings: Settings
    registry: Registry
    linter: Linter
    spec: LinterSpec

    def finish(self, report: Report) -> Report:
        """The report as the user sees it (:func:`finished`)."""
        return finished(report, self.settings, self.registry, self.unfixable)

    def is_reported(self, finding: Finding) -> bool:
        """Whether a finding reaches the report (per-path ignores, the baseline)
        and may be fixed (not an ``unfixable`` rule's). A finding the baseline
        records is accepted as it is: --fix and --diff leave it, as ruff fixes
        no diagnostic a ``noqa`` hides and clang-tidy none ``NOLINT`` hides (and
        ESLint's RFC 146 for its suppressions file). Of several findings of one
        fingerprint, none is fixed while the baseline records any."""
        if finding.code in self.unfixable or self._known(finding):
            return False
        alone = Report((FileResult(finding.location.file, findings=(finding,)),))
        return bool(self.finish(alone).findings)

    def _known(self, finding: Finding) -> bool:
        if self._baseline is None:
            return False
        from .baseline import fingerprint

        known, base_dir = self._baseline
        return known[fingerprint(finding, base_dir)] > 0

    @cached_property
    def _baseline(self) -> tuple[Counter, Path] | None:
        """The --baseline's fingerprint counts and the folder its paths are
        relative to (None without one)."""
        request = self.request
        if not request.baseline or request.write_baseline:
            return None
        known = _load_baseline(request)
        assert known is not None
        return known, Path(request.baseline).resolve().parent

    @cached_property
    def unfixable(self) -> frozenset[str]:
        """The codes of the rules whose fixes --fix never applies."""
        return unfixable_codes(self.settings, self.registry)


def unfixable_codes(settings: Settings, registry: Registry) -> frozenset[str]:
    """The codes of the rules ``settings`` makes ``unfixable``."""
    return frozenset(r.code for r in registry.rules if matches_any(r, settings.unfixable))


def finished(
    report: Report,
    settings: Settings,
    registry: Registry,
    unfixable: frozenset[str] | None = None,
) -> Report:
    """``report`` (linted under ``settings``) as the user sees it: per-path
    ignores applied, and no fix on a finding of a rule whose fixes --fix never
    applies (``Report.unfixable``): those the configuration makes ``unfixable``,
    and every rule's under ``variants``, which check --fix refuses (the API's
    findings then carry none either, as the reports offer none). What check
    does after linting, and merge again under the configuration it is given.
    ``unfixable``: the settings' codes, when known."""
    rules = registry.rules
    report = apply_path_ignores(report, settings.per_path_ignores, settings.base_dir, rules)
    if unfixable is None:
        unfixable = unfixable_codes(settings, registry)
    if settings.variants:
        unfixable = frozenset(rule.code for rule in rules)
    report = without_fixes(report, unfixable)
    severities = tuple(sorted(severity_overrides(registry, settings).items()))
    return replace(report, unfixable=unfixable, severities=severities)


def finished_by_file(
    report: Report, settings_of: Callable[[str], Settings | None], registry: Registry
) -> Report:
    """``report`` as check shows it when each file is linted under its own
    ``settings_of(file)`` (:func:`finished`; a file without is left as it is):
    ``merge --config`` judges the merged files again under the configuration
    it is given, as a check with it would (its per-path ignores and
    ``unfixable`` rules)."""
    parts: dict[int, tuple[Settings, list[int]]] = {}
    for index, result in enumerate(report.files):
        settings = settings_of(result.file)
        if settings is not None:
            parts.setdefault(id(settings), (settings, []))[1].append(index)
    files = list(report.files)
    unfixable_of: list[frozenset[str]] = [frozenset()] * len(files)
    severities_of: list[tuple[tuple[str, Severity], ...]] = [()] * len(files)
    for settings, indexes in parts.values():
        part = finished(Report(tuple(files[i] for i in indexes)), settings, registry)
        for index, result in zip(indexes, part.files, strict=True):
            files[index], unfixable_of[index] = result, part.unfixable
            severities_of[index] = part.severities
    if not parts:
        return report
    judged = replace(report, files=tuple(files))
    if len(parts) == 1 and len(next(iter(parts.values()))[1]) == len(files):
        # One configuration judged them all.
        return replace(judged, unfixable=unfixable_of[0], severities=severities_of[0])
    return replace(
        judged,
        unfixable=frozenset().union(*unfixable_of),
        unfixable_by_file=tuple((r.file, u) for r, u in zip(files, unfixable_of, strict=True)),
        severities_by_file=tuple((r.file, s) for r, s in zip(files, severities_of, strict=True)),
    )


def rejudged(
    report: Report, settings_of: Callable[[str], Settings | None], registry: Registry
) -> Report:
    """``report``'s findings as a check under ``settings_of(file)`` would have
    them (a file without is left as it is): those of the rules it does not
    select left out, and each other's severity the one it sets, else the
    rule's under the finding's profile, as the linter gives it
    (engine/linter.py, ``Linter._finding``). ``merge --config`` re-applies its
    configuration so; a finding of a rule the check did not run cannot be
    added. ST001 and codes no installed rule has are left as they are."""
    by_code = {rule.code: rule for rule in registry.rules}
    judges: dict[int, tuple[Settings, frozenset[str], dict[str, Severity]]] = {}
    renamed: dict[Finding, Finding] = {}
    files = []
    for result in report.files:
        settings = settings_of(result.file)
        if settings is None:
            files.append(result)
            continue
        if id(settings) not in judges:
            codes = frozenset(rule.code for rule in make_rules(registry, settings))
            judges[id(settings)] = (settings, codes, severity_overrides(registry, settings))
        _, codes, severities = judges[id(settings)]
        kept = []
        for finding in result.findings:
            rule = by_code.get(finding.code)
            if rule is None or rule.code in UNIGNORABLE:
                kept.append(finding)
            elif rule.code in codes:
                severity = severities.get(rule.code) or _profile_severity(rule, finding.profile)
                if severity is not finding.severity:
                    renamed[finding] = replace(finding, severity=severity)
                kept.append(renamed.get(finding, finding))
        # Judged by that configuration now, as check under it records.
        files.append(replace(result, findings=tuple(kept), config=settings.source))
    return replace(
        report,
        files=tuple(files),
        baseline_held=frozenset(renamed.get(f, f) for f in report.baseline_held),
    )


def _profile_severity(rule: type[Rule], profile: str | None) -> Severity:
    """A finding's severity under ``profile`` before the configuration's: a
    generic rule's as the profile changes it (profiles/model.py, ``judge``)."""
    known = PROFILES.get(profile) if profile is not None else None
    change = known.change_for(rule.code) if known and rule.profile is None else None
    return change.severity if change and change.severity else rule.severity


def without_fixes(report: Report, codes: frozenset[str]) -> Report:
    """``report`` with no fix on the findings of the rules ``codes`` names:
    every format, the editor and the validation plugins then offer none, as
    ``--fix`` applies none. Ruff does the same: its linter removes the fix of
    every diagnostic of an ``unfixable`` rule after the rules ran
    (https://github.com/astral-sh/ruff/pull/7919, crates/ruff_linter/src/linter.rs)."""
    if not codes or not any(f.fix is not None and f.code in codes for f in report.findings):
        return report
    files = tuple(
        replace(
            result,
            findings=tuple(
                replace(f, fix=None) if f.fix is not None and f.code in codes else f
                for f in result.findings
            ),
        )
        for result in report.files
    )
    return replace(report, files=files)


def prepare(request: Request, registry: Registry | None = None) -> Prepared:
    """Load the rules and the configuration, and build the linter. Raises
    :class:`RequestError` for a bad configuration or a rule plugin that fails."""
    from ..registry import RegistryError

    settings: Settings | None = None
    try:
        check_request(request)
        registry = registry or build_registry()
        settings = resolve_settings(request)
        linter = make_linter(settings, registry, full_composition=request.full_composition)
    except (ConfigError, RegistryError) as exc:
        message = str(exc)
        if isinstance(exc, ConfigError) and settings is not None:
            message = with_key_line(message, settings)  # a code or option the rules deny
        raise RequestError(message) from exc
    spec = LinterSpec(
        settings,
        request.full_composition,
        settings.max_variant_combinations if settings.variants else None,
    )
    return Prepared(request, settings, registry, linter, spec)


# -- the run ------------------------------------------------------------------------


def run(request: Request, registry: Registry | None = None) -> Outcome:
    """Carry out a check request. Raises :class:`RequestError` when it cannot
    start; a file that cannot be linted is an error result, never an exception.
    Files whose nearest configuration is not the one found from the first path
    are linted with theirs (running/hierarchy.py)."""
    try:
        return _run(request, registry)
    except ExecutionError as exc:  # workers that fixed or planned roots, not lint_as_asked's
        raise RequestError(str(exc)) from None
    except SchemasMissing as exc:  # this process's USD: a cache lookup, a fix, a lint
        from .address_space import schemas_missing

        raise SchemasRefused(schemas_missing(exc)) from None


def _run(request: Request, registry: Registry | None) -> Outcome:
    with reading_once():  # each configuration file read once in the run
        prepared = prepare(request, registry)
        notes: list[str] = []
        files = collect_targets(prepared, notes)
        parts = configuration_parts(prepared, files)
        if parts is None:
            outcome = _run_files(prepared, files, notes)
        else:
            # Every part is checked, then fixed, before any is linted: a part's fix
            # of a layer another part's stages compose (a shared sublayer) must not
            # leave that part's report describing the layer as it was.
            runs = [_plan_files(part, found, []) for part, found in parts]
            for files_run in runs:
                _fix_files(files_run)
            _once_per_layer(runs)
            ahead = _lint_parts_together(runs, notes)
            outcomes = [_report_files(files_run, ahead) for files_run in runs]
            outcome = _joined(prepared, outcomes, files, notes)
    # The environment's problems (engine/plugins.py), known once the files are linted.
    return replace(outcome, notes=(*plugin_notes(), *outcome.notes))


def _lint_parts_together(runs: Sequence[_FilesRun], notes: list[str]) -> dict[str, FileResult]:
    """The files of a split run's parts, as their fixes left them, linted by one
    set of workers, each file with its own configuration's linter (workers of
    their own cost about 40 ms a configuration: benchmarks/run.py --only
    configs, and a part's own fixing worker as much again); the results each
    part's run then reports. Empty where a part lints otherwise: inside the
    stages its ``roots`` name, or --fix-to's stage with the overrides. A stage
    whose fixing ran out of time is not linted again."""
    request = runs[0].prepared.request
    roots = any(run.prepared.settings.roots and request.use_roots for run in runs)
    if roots or (request.fix is not None and request.fix.fix_to):
        return {}
    jobs = []
    for run in runs:
        failed = {result.file for result in run.fix_failed}
        targets = [target for target in run.targets if target not in failed]
        jobs.append((run.prepared, targets, _open_cache(run.prepared, notes)))
    return _lint_together(request, jobs)


def configuration_parts(
    prepared: Prepared, files: Sequence[str]
) -> list[tuple[Prepared, list[str]]] | None:
    """The run split by configuration (running/hierarchy.py): each nearest
    configuration's preparation and files; None when every file has the
    run's. The files a walk found that a part's own exclusions skip are left
    out, as a walk reading each folder's configuration would leave them, and
    so are the files given that they skip when it sets force-exclude."""
    request = prepared.request
    if request.config is not None or request.isolated or request.stdin is not None:
        return None
    try:
        # A run with the user's own configuration has it where no project's is found.
        found = None if prepared.settings.user_level else prepared.settings.source
        groups = configuration_groups(files, found)
        fallback = fallback_settings() if groups and any(g.config is None for g in groups) else None
    except ConfigError as exc:
        raise RequestError(str(exc)) from exc
    if groups is None:
        return None
    given = given_files(request.paths)
    # A path given: skipped where a walk from the outermost configured folder would.
    given_skipped = walk_skips(Exclusions.of(prepared.settings), folder_exclusions(prepared))
    parts = []
    for group in groups:
        # --write-baseline records the joined report, once.
        own = replace(request, config=group.config, isolated=group.config is None)
        if group.config is None and fallback is not None and fallback.source:
            own = replace(request, config=fallback)  # the user's own configuration
        part = prepare(replace(own, write_baseline=None), prepared.registry)
        walked_skipped = walk_skips(Exclusions.of(part.settings))
        judged = part.settings.force_exclude
        kept = [
            f
            for f in group.files
            if not (
                (judged and given_skipped(f)) if os.path.normpath(f) in given else walked_skipped(f)
            )
        ]
        parts.append((part, kept))
    return parts


def _joined(
    prepared: Prepared, outcomes: Sequence[Outcome], files: Sequence[str], notes: list[str]
) -> Outcome:
    """One outcome of a split run's parts: the files in the order they came,
    every note once, the worst exit status."""
    request = prepared.request
    rules = {type(rule).code: rule for outcome in outcomes for rule in outcome.rules}
    place = {os.path.normpath(file): index for index, file in enumerate(files)}
    results = [result for outcome in outcomes for result in outcome.report.files]
    results.sort(key=lambda result: place.get(os.path.normpath(result.file), len(place)))
    report = Report(
        tuple(results),
        applied_fixes=tuple(f for o in outcomes for f in o.report.applied_fixes),
        unapplied_fixes=tuple(f for o in outcomes for f in o.report.unapplied_fixes),
        unfixable=frozenset().union(*(o.report.unfixable for o in outcomes)),
        unfixable_by_file=tuple(
            (r.file, o.report.unfixable) for o in outcomes for r in o.report.files
        ),
        severities_by_file=tuple(
            (r.file, o.report.severities) for o in outcomes for r in o.report.files
        ),
        baseline_held=frozenset().union(*(o.report.baseline_held for o in outcomes)),
    )
    # A part's notes that count (known findings, fixes) count its own: the
    # joined run says the totals instead.
    dropped = sum(outcome.baseline_dropped for outcome in outcomes)
    stale = sum(outcome.baseline_stale for outcome in outcomes)
    counted = {
        note
        for o in outcomes
        for note in _counted_notes(request, o.report, o.baseline_dropped, o.baseline_stale)
    }
    notes += [note for outcome in outcomes for note in outcome.notes if note not in counted]
    _apply_baseline(report, None, prepared, notes)  # --write-baseline: all of it
    notes.extend(_counted_notes(request, report, dropped, stale))
    status = max((outcome.exit_status for outcome in outcomes), default=EXIT_OK)  # 2 > 1 > 0
    if request.write_baseline:
        status = exit_status(report, "never", baseline_written=True)
    return Outcome(
        report,
        prepared.settings,
        tuple(rules.values()),
        status,
        diffs=tuple(diff for outcome in outcomes for diff in outcome.diffs),
        notes=tuple(dict.fromkeys(notes)),
        fix_errors=tuple(error for outcome in outcomes for error in outcome.fix_errors),
        baseline=outcomes[0].baseline if outcomes else None,
        baseline_dropped=dropped,
        baseline_stale=stale,
        parts=tuple(outcomes),
    )


@record
class _FilesRun:
    """One configuration's run of its files, between its phases: planned (the
    request checked, the targets known), fixed, reported."""

    prepared: Prepared
    notes: list[str]
    #: The baseline read (--baseline).
    known: Counter | None
    targets: Sequence[str]
    plan: ContextPlan | None
    #: ``check -``'s text, as its fixes leave it.
    stdin: TextLayer | None
    fixed: FixRun | None = None
    fix_failed: tuple[FileResult, ...] = ()


def _once_per_layer(runs: Sequence[_FilesRun]) -> None:
    """--diff over a split run's parts: one patch per layer and one fix per
    edit, as over one part (FixRun.once_per_layer). Parts whose stages share a
    layer each start from its file, so each showed the same patch of it (a
    second copy does not apply) and counted its fix again; --fix writes it once."""
    from ..fixing import FixRun

    fixed = [run.fixed for run in runs if run.fixed is not None]
    request = runs[0].prepared.request if runs else None
    if len(fixed) < 2 or request is None or request.fix is None or request.fix.write:
        return
    joined = FixRun()
    for part in fixed:
        joined.extend(part)
    joined.once_per_layer()
    kept = {id(outcome) for outcome in joined.outcomes}
    for index, part in enumerate(fixed):
        part.outcomes[:] = [outcome for outcome in part.outcomes if id(outcome) in kept]
        part.diffs[:] = joined.diffs if index == 0 else []


def _run_files(
    prepared: Prepared,
    files: Sequence[str],
    notes: list[str],
    ahead: Mapping[str, FileResult] | None = None,
) -> Outcome:
    """The run of ``files`` (collected) with one configuration; ``ahead``: the
    results of files already linted (_lint_parts_together)."""
    run = _plan_files(prepared, files, notes)
    _fix_files(run)
    return _report_files(run, ahead)


def _plan_files(prepared: Prepared, files: Sequence[str], notes: list[str]) -> _FilesRun:
    """Check the request and find the targets; raises RequestError before
    anything is fixed."""
    request, settings = prepared.request, prepared.settings
    notes[:0] = unignorable_notes(prepared.registry, settings)
    known = _load_baseline(request)
    _check_fix_request(request, settings)
    targets, plan = plan_targets(prepared, files)
    notes.extend(plan.notes if plan is not None else ())
    refuse_outputs_on_inputs(request, settings, targets)
    # A text whose name force-exclude leaves out is neither linted nor fixed.
    stdin = request.stdin if targets else None
    return _FilesRun(prepared, notes, known, targets, plan, stdin)


def _fix_files(run: _FilesRun) -> None:
    """Apply (or, for --diff, compute) the fixes of the run's targets."""
    prepared, request = run.prepared, run.prepared.request
    if request.fix is not None and run.stdin is not None:
        run.fixed, run.stdin = run.stdin.fix(prepared)  # nothing is written: the text is the output
    elif request.fix is not None and request.stdin is None:
        run.fixed, run.fix_failed = _run_fixes(prepared, run.targets, run.plan)


def _report_files(run: _FilesRun, ahead: Mapping[str, FileResult] | None = None) -> Outcome:
    """Lint the targets (as the fixes left them) and make the run's outcome."""
    prepared, notes, known, plan = run.prepared, run.notes, run.known, run.plan
    request, settings = prepared.request, prepared.settings
    stdin, fixed = run.stdin, run.fixed
    report = _lint_targets(prepared, stdin, run.targets, fixed, run.fix_failed, notes, ahead or {})
    if plan is not None:
        report = replace(report, files=plan.failed + report.files)
        report = plan.narrow(report)
    report = prepared.finish(report)
    if settings.source:  # which configuration judged each file, for the report
        report = replace(
            report, files=tuple(replace(r, config=settings.source) for r in report.files)
        )
    notes.extend(note for result in report.files for note in result.notes)
    report, dropped, stale = _apply_baseline(report, known, prepared, notes)
    notes.extend(_baseline_note(request, dropped, stale))
    status = exit_status(report, settings.fail_on, baseline_written=bool(request.write_baseline))
    outcome = Outcome(
        report,
        settings,
        prepared.linter.rules,
        status,
        notes=tuple(notes),
        baseline=known,
        baseline_dropped=dropped,
        baseline_stale=stale,
    )
    if fixed is not None:
        outcome = _with_fixes(outcome, fixed, request)
    if request.stdin is not None and request.fix is not None and request.fix.write:
        # The fixed text; one force-exclude left out, as it came.
        outcome = replace(outcome, text=(stdin or request.stdin).text)
    return outcome


def _check_fix_request(request: Request, settings: Settings) -> None:
    if settings.variants and request.fix is not None:
        raise RequestError(
            "--variants (or config 'variants') cannot be combined with --fix, --diff or "
            "--fix-to; --config 'variants = false' turns the configuration's off for one run"
        )
    if request.fix is not None and request.fix.fix_to and request.fix.write is False:
        raise RequestError("use either --diff or --fix-to, not both")
    fix_to = request.fix is not None and request.fix.fix_to
    if request.stdin is not None and (fix_to or request.shard is not None):
        raise RequestError(
            "'-' (a layer on standard input) cannot be combined with --fix-to or --shard: give "
            "the file's path"
        )


def collect_targets(prepared: Prepared, notes: list[str]) -> list[str]:
    """The files the request names, folders walked (a note for each folder
    with none)."""
    request = prepared.request
    exclusions = Exclusions.of(prepared.settings)
    if request.stdin is not None:  # a text, linted as its own stage
        name = request.stdin.name
        return [] if force_excluded(name, exclusions, folder_exclusions(prepared)) else [name]
    empty: list[str] = []
    files = collect_files(request.paths, empty, exclusions, folder_exclusions(prepared))
    notes.extend(map(no_usd_files, empty))
    return files


def no_usd_files(folder: str) -> str:
    """The note on a folder given that holds no USD file (likely a mistake)."""
    return f"warning: {folder}: no USD files (.usd, .usda, .usdc, .usdz) in it"


def folder_exclusions(prepared: Prepared) -> FolderExclusions | None:
    """The exclusions of the configuration each folder keeps (the flags applied,
    as configuration_parts prepares it), for a walk and for force-exclude; None
    when the run has one configuration (--config, --isolated)."""
    request = prepared.request
    if request.config is not None or request.isolated:
        return None
    run_config = prepared.settings.source and os.path.realpath(prepared.settings.source)
    known: dict[str, Exclusions | None] = {}

    def of_folder(folder: str) -> Exclusions | None:
        if folder in known:  # force-exclude asks again for each path given below it
            return known[folder]
        try:
            # Named as running/hierarchy.py names it (its errors too): resolved.
            found = config_file_in(Path(folder).resolve())
            own = None
            if found is not None and str(found) == run_config:
                own = Exclusions.of(prepared.settings)
            elif found is not None:
                own = Exclusions.of(resolve_settings(replace(request, config=str(found))))
        except ConfigError as exc:
            raise RequestError(str(exc)) from exc
        known[folder] = own
        return own

    return of_folder


def plan_targets(
    prepared: Prepared, files: Sequence[str]
) -> tuple[Sequence[str], ContextPlan | None]:
    """The files of the run (collect_targets), their shard, and with config
    ``roots`` the plan that lints them inside the stages that use them."""
    request, settings = prepared.request, prepared.settings
    if request.stdin is not None:
        return files, None
    plan = None
    if settings.roots and request.use_roots:
        from .roots import plan_from_settings  # USD's dependency tools: only for roots

        plan = plan_from_settings(
            files, settings, timeout=request.timeout, jobs=request.jobs or default_jobs()
        )
    if request.shard is not None:
        from .shards import select_plan_shard, select_shard

        if plan is not None:
            plan = select_plan_shard(plan, request.shard, settings.base_dir)
        else:
            files = select_shard(files, request.shard, settings.base_dir)
    return (plan.files if plan else files), plan


def _lint_targets(
    prepared: Prepared,
    stdin: TextLayer | None,
    targets: Sequence[str],
    fixed: FixRun | None,
    fix_failed: tuple[FileResult, ...],
    notes: list[str],
    ahead: Mapping[str, FileResult],
) -> Report:
    """The report of ``targets``: what remains with --fix-to's overrides, else
    each file linted (after its fixes), but a stage whose fixing ran out of
    time, which is reported as that, not linted again. ``stdin``: the text to
    lint instead (``check -``), as its fixes left it."""
    if stdin is not None:  # in-process, never cached: it is no file
        return Report((stdin.lint(prepared),))
    if not targets:  # nothing to lint: no cache to open
        return Report(())
    fix = prepared.request.fix
    if fixed is not None and fix is not None and fix.fix_to:
        return Report(tuple(fixed.remaining) + fix_failed)
    failed = {result.file: result for result in fix_failed}
    todo = [target for target in targets if target not in failed]
    if all(target in ahead for target in todo):
        linted = iter([ahead[target] for target in todo])
    else:
        linted = iter(_lint(prepared, todo, _open_cache(prepared, notes)))
    return Report(tuple(failed[t] if t in failed else next(linted) for t in targets))


def _with_fixes(outcome: Outcome, fixed: FixRun, request: Request) -> Outcome:
    """The outcome of a run that fixed (or, for --diff, would fix)."""
    assert request.fix is not None
    report = replace(outcome.report, applied_fixes=fixed.applied, unapplied_fixes=fixed.unapplied)
    notes = [*outcome.notes, *fixed.notes, *_fix_notes(report, dry_run=not request.fix.write)]
    status = outcome.exit_status
    if fixed.errors:
        status = EXIT_TOOL_ERROR
    elif not request.fix.write and status != EXIT_TOOL_ERROR:
        # --diff answers "is a fix pending?" (as ruff does), not "are there findings?".
        status = EXIT_FINDINGS if report.applied_fixes else EXIT_OK
    return replace(
        outcome,
        report=report,
        exit_status=status,
        diffs=tuple(fixed.diffs),
        notes=tuple(notes),
        fix_errors=tuple(fixed.errors),
    )


def refuse_outputs_on_inputs(request: Request, settings: Settings, targets: Sequence[str]) -> None:
    """Raise RequestError when the report or the baseline would be written
    onto a file this run reads: a linted file, a layer, the configuration or
    the baseline read."""
    from .outputs import OutputOnInput, refuse_inputs, refuse_one_file_twice

    outputs = [(request.output, "the report"), (request.write_baseline, "the baseline")]
    inputs = [*targets, *(p for p in (settings.source, request.baseline) if p)]
    fix_to = request.fix.fix_to if request.fix is not None else None
    try:
        refuse_one_file_twice([*outputs, (fix_to, "the --fix-to overrides")])
        refuse_inputs(outputs, inputs)
    except OutputOnInput as exc:
        raise RequestError(str(exc)) from None


def _lint(
    prepared: Prepared, files: Sequence[str], cache: ResultCache | None = None
) -> tuple[FileResult, ...]:
    """Lint ``files`` (in input order); with a cache, only those whose stored
    result is stale, and store what is linted."""
    results = _lint_together(prepared.request, [(prepared, files, cache)])
    return tuple(results[path] for path in files)


def _lint_together(
    execution: Execution, jobs: Sequence[tuple[Prepared, Sequence[str], ResultCache | None]]
) -> dict[str, FileResult]:
    """Each job's files linted with its linter, all in one set of workers; with
    a job's cache, only those whose stored result is stale (the workers store
    what they lint)."""
    results: dict[str, FileResult] = {}
    todo: dict[str, int] = {}  # each file to lint, with its job
    for index, (_prepared, files, cache) in enumerate(jobs):
        for path in files:
            hit = cache.lookup(path) if cache is not None else None
            if hit is not None:
                results[path] = hit
            else:
                todo[path] = index
    specs = tuple(replace(prepared.spec, cache=cache) for prepared, _files, cache in jobs)
    if todo:
        if len(specs) == 1:  # in this process, the linter already built serves
            linted = lint_as_asked(
                execution, list(todo), specs[0], specs[0].wrap(jobs[0][0].linter)
            )
        else:
            linted = lint_as_asked(execution, list(todo), LintersByFile(specs, todo))
        results.update(zip(todo, linted, strict=True))
    # Worker processes store into copies of a job's cache, whose counts this
    # process never sees: a job that had files linted may have stored entries.
    for index in sorted(set(todo.values())):
        cache = jobs[index][2]
        if cache is not None:
            cache.prune()
    return results


class Execution(Protocol):
    """How a request has its files linted (a check's Request, spec's InspectRequest)."""

    @property
    def jobs(self) -> int | None: ...
    @property
    def timeout(self) -> float | None: ...
    @property
    def progress(self) -> bool | None: ...
    @property
    def supervision(self) -> Supervision | None: ...


def lint_as_asked(
    execution: Execution,
    files: Sequence[str],
    linter_factory: LinterFactory,
    linter: FileLinter | None = None,
) -> tuple[FileResult, ...]:
    """``lint_paths`` with the request's workers, time limit, progress bar and
    supervisor; workers that cannot start are the run's RequestError."""
    try:
        return lint_paths(
            files,
            linter=linter,
            linter_factory=linter_factory,
            jobs=execution.jobs or default_jobs(),
            timeout=execution.timeout,
            progress=execution.progress,
            supervision=execution.supervision,
        )
    except ExecutionError as exc:
        raise RequestError(str(exc)) from None
    except SchemasMissing as exc:  # linted in this process
        from .address_space import schemas_missing

        raise SchemasRefused(schemas_missing(exc)) from None


def _open_cache(prepared: Prepared, notes: list[str]) -> ResultCache | None:
    """The result cache the request asks for, or None (with a note when the
    folder cannot be written: the run goes on without it)."""
    request = prepared.request
    if not request.cache:
        return None
    from .result_cache import ForeignFolder, ResultCache, cache_folder, run_key

    folder = cache_folder(prepared.settings, request.cache_dir)
    key = run_key(
        prepared.linter,
        prepared.settings,
        variant_combinations=prepared.spec.variant_combinations,
        profile_choice=profile_choice_key(prepared.settings),
    )
    cache = ResultCache(folder, key)
    try:
        problem = cache.prepare()
    except ForeignFolder as exc:
        raise RequestError(str(exc)) from None
    if problem is not None:
        notes.append(f"{problem}; results are not cached")
        return None
    return cache


def exit_status(report: Report, fail_on: str, *, baseline_written: bool = False) -> int:
    """2 when a file could not be linted; 0 after writing a baseline (today's
    findings are accepted); else 1 when a finding is at or above ``fail_on``."""
    if report.errored_files:
        return EXIT_TOOL_ERROR
    if baseline_written:
        return EXIT_OK
    return EXIT_FINDINGS if fails(report, fail_on) else EXIT_OK


def fails(report: Report, fail_on: str) -> bool:
    """True when a finding is at or above the ``fail_on`` threshold."""
    if fail_on == "never":
        return False
    threshold = Severity.parse(fail_on).rank
    return any(f.severity.rank >= threshold for f in report.findings)


# -- fixing ---------------------------------------------------------------------------


def _run_fixes(
    prepared: Prepared, files: Sequence[str], plan: ContextPlan | None = None
) -> tuple[FixRun, tuple[FileResult, ...]]:
    """Apply (or, for --diff, compute) the fixes on every stage, one stage after
    another, and say which stages could not be fixed (error results). With a
    time limit each stage is fixed in a worker process that is killed when it
    runs past it (a FIFO in a layer stack blocks USD forever); without one, in
    this process. With ``plan`` (``roots``), only the findings the report keeps
    are fixed: those authored in the layers given."""
    from ..fixing import FixError, FixRun, fix_files

    wanted = prepared.request.fix
    assert wanted is not None
    if wanted.fix_to and len(files) != 1:
        why = f"got {len(files)} files"
        if plan is not None and plan.roots:
            why = f"the layers given are linted in {len(files)} stages (roots): give --no-roots"
        raise RequestError(f"--fix-to writes the overrides of one stage; {why}")
    if not prepared.request.timeout:
        try:
            options = _fix_options(prepared, excluded_from_linting(prepared))
            run = fix_files(prepared.linter, files, options, keep=_fix_keep(prepared, plan))
        except FixError as exc:
            raise RequestError(str(exc)) from None
        return run, ()
    # One worker, so that stages sharing a layer are still fixed one after another.
    part = replace(prepared.request, config=prepared.settings, isolated=False)
    fixing = _Fixing(part, plan, given=prepared.request)
    results = Pool(fixing, 1, prepared.request.timeout, handle=_fix_in_worker).run(files)
    refused = [r for r in results if isinstance(r, _FixRefused)]
    if refused:
        raise RequestError(refused[0].reason)
    run = FixRun()
    for result in results:
        if isinstance(result, FixRun):
            run.extend(result)
    if not wanted.write:
        run.once_per_layer()
    return run, tuple(r for r in results if isinstance(r, FileResult))


def _fix_options(prepared: Prepared, excluded: Callable[[str], bool]) -> FixOptions:
    from ..fixing import FixOptions

    wanted = prepared.request.fix
    assert wanted is not None
    return FixOptions(
        unsafe=wanted.unsafe, write=wanted.write, fix_to=wanted.fix_to, excluded=excluded
    )


def excluded_from_linting(prepared: Prepared) -> Callable[[str], bool]:
    """Whether a walk of the run would leave a path out (exclude, .gitignore,
    each folder's own configuration): fixes do not edit such a layer that a
    stage composes, as ruff never edits an excluded file."""
    return walk_skips(Exclusions.of(prepared.settings), folder_exclusions(prepared))


@record(frozen=True)
class _Fixing:
    """A worker's fixer, built from the request (picklable), with the run's
    roots plan."""

    request: Request
    plan: ContextPlan | None = None
    #: The request as given (its configuration found per folder): what a walk
    #: leaves out (FixOptions.excluded) is judged by it.
    given: Request | None = None

    def __call__(self) -> tuple[Prepared, ContextPlan | None, Callable[[str], bool]]:
        prepared = prepare(self.request)
        given = replace(prepared, request=self.given or self.request)
        return prepared, self.plan, excluded_from_linting(given)


@record(frozen=True)
class _FixRefused:
    """The fixing cannot start (FixError), said from a worker."""

    reason: str


def _fix_in_worker(
    state: tuple[Prepared, ContextPlan | None, Callable[[str], bool]], path: str
) -> object:
    from ..fixing import FixError, fix_files
    from .workers import hold_deadline

    prepared, plan, excluded = state
    assert prepared.request.fix is not None
    # A kill past --timeout while a file is written would leave its write half-done.
    options = replace(_fix_options(prepared, excluded), before_writing=hold_deadline)
    try:
        return fix_files(prepared.linter, [path], options, keep=_fix_keep(prepared, plan))
    except FixError as exc:
        return _FixRefused(str(exc))


def _fix_keep(prepared: Prepared, plan: ContextPlan | None) -> Callable[[Finding], bool]:
    """The findings to fix: those the report keeps (with ``roots``, those
    authored in the layers given, as ContextPlan.narrow keeps them)."""
    if plan is None:
        return prepared.is_reported
    return lambda finding: prepared.is_reported(finding) and plan.keeps(finding)


def _counted_notes(request: Request, report: Report, dropped: int, stale: int) -> list[str]:
    """The notes of a run that count what it did: the known findings the
    baseline hid and those it records that are gone, the fixes not applied and
    those --diff would apply."""
    notes = _baseline_note(request, dropped, stale)
    if request.fix is not None:
        notes += _fix_notes(report, dry_run=not request.fix.write)
    return notes


def _fix_notes(report: Report, dry_run: bool) -> list[str]:
    """Each reason a fix was not applied, once, and what --diff would do."""
    notes = []
    by_reason: dict[str, list[str]] = {}
    for fix in report.unapplied_fixes:
        by_reason.setdefault(fix.reason or "", []).append(fix.code)
    for reason, codes in by_reason.items():
        kinds = ", ".join(sorted(set(codes)))
        notes.append(f"{_count(len(codes), 'fix', 'fixes')} not applied ({kinds}): {reason}")
    if dry_run:
        count = _count(len(report.applied_fixes), "fix", "fixes")
        notes.append(f"--diff: {count} would be applied")
    return notes


# -- baseline -------------------------------------------------------------------------


def _load_baseline(request: Request) -> Counter | None:
    """The baseline's fingerprint counts (None without one); read before
    linting so a missing or corrupt file fails fast."""
    if request.baseline and request.write_baseline:
        raise RequestError("use either --baseline or --write-baseline, not both")
    if not request.baseline:
        return None
    from .baseline import BaselineError, load_baseline

    try:
        return load_baseline(request.baseline)
    except BaselineError as exc:
        raise RequestError(str(exc)) from None


def _apply_baseline(
    report: Report, known: Counter | None, prepared: Prepared, notes: list[str]
) -> tuple[Report, int, int]:
    """Keep only new findings (baseline), with how many the baseline hid and
    how many it records that are gone (baseline.stale_count); or record them
    all (write_baseline)."""
    request = prepared.request
    if request.write_baseline:
        from .baseline import BaselineError, write_baseline

        try:
            count = write_baseline(report, request.write_baseline)
        except BaselineError as exc:
            raise RequestError(str(exc)) from None
        notes.append(f"recorded {_count(count, 'finding')} in {request.write_baseline}")
    elif known is not None and request.baseline:
        from .baseline import fingerprint, new_findings, stale_count

        base_dir = Path(request.baseline).resolve().parent
        codes = frozenset(type(rule).code for rule in prepared.linter.rules)
        variants = prepared.settings.variants
        stale = stale_count(report, known, base_dir, codes.union(UNIGNORABLE), variants)
        kept, dropped = new_findings(report, known, base_dir)
        # A new finding of a fingerprint the baseline records (a second one at
        # the same place) is reported, but --fix leaves it (is_reported): say
        # so, rather than count it fixable.
        held = frozenset(
            f for f in kept.findings if f.fix is not None and known[fingerprint(f, base_dir)] > 0
        )
        return replace(kept, baseline_held=held), dropped, stale
    return report, 0, 0


def _baseline_note(request: Request, dropped: int, stale: int) -> list[str]:
    """The lines that say how many known findings the report leaves out, and
    how many the baseline records that the files linted no longer have."""
    notes = []
    if dropped:
        notes.append(f"{_count(dropped, 'finding')} recorded in {request.baseline} not shown")
    if stale:
        notes.append(
            f"{_count(stale, 'finding')} recorded in {request.baseline} no longer "
            f"{'occurs' if stale == 1 else 'occur'} in the files linted: write the baseline "
            "again (--write-baseline) to drop them, or it hides them when they come back"
        )
    return notes


def _count(count: int, one: str, many: str | None = None) -> str:
    return f"{count} {one if count == 1 else (many or one + 's')}"


__all__ = [
    "EXIT_FINDINGS",
    "EXIT_OK",
    "EXIT_TOOL_ERROR",
    "FixRequest",
    "LinterSpec",
    "Outcome",
    "Prepared",
    "Request",
    "RequestError",
    "SchemasRefused",
    "exit_status",
    "fails",
    "make_linter",
    "make_rules",
    "prepare",
    "run",
]
