"""The rule engine: open a stage, walk it once, run the rules, make findings.

It knows rules (through :mod:`usdrender_lint.api`) and the data model, never a
formatter, the configuration or the command line.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import field
from typing import Any, Generic, Literal, TypeVar

from pxr import Sdf, Tf, Usd

from .. import debug
from ..api import Context, Diagnostic, Fix, FullStageRequired, Rule, schemas
from ..api.cache import lint_cache
from ..api.resolve import forget_prim_answers, know_usable
from ..layers.crate import crate_structure_problem
from ..layers.files import layer_identifier, real_path, resolver_context_key, unreadable_reason
from ..layers.nesting import nesting_problem
from ..model import (
    INTERNAL_ERROR_CODE,
    INTERNAL_ERROR_NAME,
    CorruptValue,
    FileResult,
    Finding,
    FixInfo,
    Location,
    Severity,
)
from ..paths import single_root
from ..records import record
from . import layer_words, partial, suppress, typed_prims
from .assets import Reads
from .locate import bounded_message, locate
from .plugins import register_plugins
from .stage import (
    STAGE_OPEN_FAILED_CODE,
    STAGE_OPEN_FAILED_NAME,
    OutOfMemory,
    StageOpenResult,
    corruption,
    open_stage,
    out_of_memory,
    out_of_memory_message,
    position_from_error,
    without_position,
)

_T = TypeVar("_T")

#: Called with the lint's Context and its findings once the rules have run
#: (see Linter.run_path).
Inspector = Callable[[Context, Sequence[Finding]], _T]


class MalformedDiagnostic(TypeError):
    """A hook yielded (or returned) what the rule API does not allow (api/rule.py):
    the rule's own mistake, said as such, not as a fault of the engine."""


def malformed(diagnostic: object) -> str | None:
    """What is wrong with a hook's yield, or None for a well-formed Diagnostic."""
    if not isinstance(diagnostic, Diagnostic):
        return f"yielded {type(diagnostic).__name__} {diagnostic!r:.60}, not a Diagnostic"
    fields = (
        ("message", diagnostic.message, str, "a str"),
        ("at", diagnostic.at, (Usd.Object, Sdf.Path, type(None)), "a USD object, Sdf.Path or None"),
        ("fix", diagnostic.fix, (Fix, type(None)), "a Fix or None"),
        ("layer", diagnostic.layer, (Sdf.Layer, type(None)), "an Sdf.Layer or None"),
    )
    for name, value, kinds, wanted in fields:
        if not isinstance(value, kinds):
            return f"yielded a Diagnostic whose {name} is {type(value).__name__}, not {wanted}"
    fix = diagnostic.fix
    if fix is not None:
        # A Fix without apply was counted "fixable with --fix", which then
        # silently left the finding in place.
        for name, value, ok, wanted in (
            ("description", fix.description, isinstance(fix.description, str), "a str"),
            ("safe", fix.safe, isinstance(fix.safe, bool), "a bool"),
            ("apply", fix.apply, callable(fix.apply), "a callable apply(stage)"),
        ):
            if not ok:
                return f"yielded a Fix whose {name} is {type(value).__name__}, not {wanted}"
    return None


class InspectionError(Exception):
    """Raised by an inspector that cannot read what it was asked for from this
    stage: the file becomes an error result with this one-line message."""


#: The words of layer_words.WORDS every lint asks its layers' files about.
_LINT_WORDS = ("clips", "timeSamples", "spline", suppress.SUPPRESSION_WORD)

#: The render prim kinds the engine collects during its walk (Context.render_prims).
RENDER_SCHEMAS: tuple[Tf.Type, ...] = (
    schemas.RenderSettings,
    schemas.RenderProduct,
    schemas.RenderVar,
    schemas.RenderPass,
)


@record(frozen=True)
class TracedFinding:
    """A finding with its Fix and origin: the code of the rule that produced it
    (an internal-error finding keeps the rule that raised) and the prim whose
    ``check_prim`` did (None for ``check_stage`` and the engine's own findings)."""

    finding: Finding
    fix: Fix | None
    rule_code: str
    prim_path: Sdf.Path | None


#: How the linted stage was composed: only what the rules read (the fast
#: path, partial.py), all of it, or None when no lint ran to its end.
Composed = Literal["partial", "full"] | None


@record(frozen=True)
class LintRun(Generic[_T]):
    """Everything one lint of a file or stage produced: its result (findings,
    notes, or why it could not be linted), each finding's Fix and origin, what
    it read when asked (``reads=True``: the result cache keys on it), how the
    stage was composed, whether the rules ran to their end, and what an
    inspector read from the linted stage."""

    result: FileResult
    #: Each finding's Fix (the callable Finding.fix drops: findings stay free of pxr objects).
    fixes: Mapping[Finding, Fix] = field(default_factory=dict)
    #: The rule code and check_prim prim behind each finding a rule made.
    origins: Mapping[Finding, tuple[str, Sdf.Path | None]] = field(default_factory=dict)
    #: What the lint read; None when not asked for.
    reads: Reads | None = None
    composed: Composed = None
    #: False when the lint stopped before its end (a file USD cannot open or read).
    completed: bool = False
    #: What the inspector read (None without one, or when no stage was linted).
    value: _T | None = None

    @property
    def findings(self) -> tuple[Finding, ...]:
        return self.result.findings

    def fix(self, finding: Finding) -> Fix | None:
        return self.fixes.get(finding)

    def traced(self) -> list[TracedFinding]:
        """Each finding with its Fix and origin (an engine finding names its own code)."""
        return [
            TracedFinding(finding, self.fixes.get(finding), *self.origin(finding))
            for finding in self.result.findings
        ]

    def origin(self, finding: Finding) -> tuple[str, Sdf.Path | None]:
        return self.origins.get(finding, (finding.code, None))


class _Trace:
    """What one lint records beside its findings, handed down the lint's calls
    (never kept on the Linter, which many lints share)."""

    __slots__ = ("fixes", "origins", "reads")

    def __init__(self, reads: bool) -> None:
        self.fixes: dict[Finding, Fix] = {}
        self.origins: dict[Finding, tuple[str, Sdf.Path | None]] = {}
        self.reads = Reads() if reads else None

    def run(
        self,
        result: FileResult,
        composed: Composed = None,
        completed: bool = False,
        value: Any = None,
    ) -> LintRun[Any]:
        if not completed:
            self.forget()  # what it recorded belongs to no finding of the result
        return LintRun(result, self.fixes, self.origins, self.reads, composed, completed, value)

    def origin_code(self, finding: Finding) -> str:
        """The code of the rule whose hook made ``finding`` (a UL000's: the rule that raised)."""
        return self.origins.get(finding, (finding.code, None))[0]

    def forget(self) -> None:
        """Drop the fixes and origins of a lint that stopped part way (the
        reads stay: they are what the lint read)."""
        self.fixes.clear()
        self.origins.clear()


class _TypeDispatch:
    """Which rules want a prim, keyed by its type name (no per-prim ``IsA``)."""

    def __init__(self, rules: Sequence[Rule]) -> None:
        self._rules = rules
        self._by_type_name: dict[str, tuple[tuple[Rule, ...], tuple[Tf.Type, ...]]] = {}
        self._wanted = {schema for rule in rules for schema in rule.prim_types}
        self._wanted.update(RENDER_SCHEMAS)
        self._tf_types = {schema: schemas.tf_type(schema) for schema in self._wanted}
        #: Type names no registered schema defines (USD composes them typeless).
        self.unknown_type_names: set[str] = set()

    def lookup(self, type_name: str) -> tuple[tuple[Rule, ...], tuple[Tf.Type, ...]]:
        """(rules to run, render schemas the type belongs to) for a type name."""
        entry = self._by_type_name.get(type_name)
        if entry is None:
            prim_type = Usd.SchemaRegistry.GetTypeFromName(type_name) if type_name else None
            if prim_type is not None and (
                prim_type.isUnknown or not Usd.SchemaRegistry.IsConcrete(prim_type)
            ):
                # USD gives a prim of an unknown or abstract type (`def RenderSettingsBase`)
                # no schema type: IsA is false for it, so no rule must treat it as typed.
                self.unknown_type_names.add(type_name)
                prim_type = None
            matches = {
                schema
                for schema, tf_type in self._tf_types.items()
                if prim_type is not None and not prim_type.isUnknown and prim_type.IsA(tf_type)
            }
            rules = tuple(r for r in self._rules if matches.intersection(r.prim_types))
            kinds = tuple(s for s in RENDER_SCHEMAS if s in matches)
            entry = self._by_type_name[type_name] = (rules, kinds)
        return entry

    def wants(self, type_name: str) -> bool:
        """True when prims of this type must be composed: a rule or the render
        prim lists want them, or no schema defines the type (unknown_type_prims)."""
        rules, kinds = self.lookup(type_name)
        return bool(rules or kinds) or type_name in self.unknown_type_names


class Linter:
    """Runs a fixed set of configured rules over files or stages.

    ``severities`` overrides rule default severities by code. With
    ``raise_errors`` a rule that raises propagates (for tests) instead of
    becoming an internal-error finding. ``lint_path`` composes only what the
    rules read when every rule declares ``partial_composition`` and that
    provably gives the same findings (partial.py); ``full_composition`` always
    composes the whole stage.
    """

    def __init__(
        self,
        rules: Sequence[Rule],
        severities: Mapping[str, Severity] | None = None,
        *,
        time_sample_cap: int = 1000,
        raise_errors: bool = False,
        known_rules: Sequence[type[Rule]] | None = None,
        full_composition: bool = False,
        profiler: Callable[[Context], Any] | None = None,
    ) -> None:
        self.rules = tuple(rules)
        #: A rule that does not declare partial_composition (every third-party
        #: rule by default) may read anything: it gets the whole stage.
        self.full_composition = full_composition or not all(
            r.partial_composition for r in self.rules
        )
        self.severities = dict(severities or {})
        self.time_sample_cap = time_sample_cap
        self.raise_errors = raise_errors
        #: Every registered rule, so a customData suppression naming a rule that
        #: was not selected is not reported as naming no rule (default: ``rules``).
        self.known_rules = known_rules
        #: Decides the renderer profile of each configuration of a lint (R2-5;
        #: usdrender_lint.profiles.Profiler). None: no profiles, the schema alone,
        #: and renderer rules (``Rule.profile``) do not run.
        self.profiler = profiler
        self._dispatch = _TypeDispatch(self.rules)
        #: Rules with a check_stage of their own (most have none: no call per file).
        self._stage_rules = tuple(r for r in self.rules if _overrides(r, "check_stage"))

    # -- entry points ---------------------------------------------------------

    def lint_path(self, path: str, *, full_composition: bool = False) -> FileResult:
        """Lint one file; never raises for a bad file (:meth:`run_path`'s result)."""
        return self.run_path(path, full_composition=full_composition).result

    def lint_stage(
        self, stage: Usd.Stage, file: str | None = None, *, texts: Mapping[str, str] | None = None
    ) -> list[Finding]:
        """The findings of an open stage (:meth:`run_stage`'s)."""
        return list(self.run_stage(stage, file, texts=texts).findings)

    def run_path(
        self,
        path: str,
        *,
        full_composition: bool = False,
        reads: bool = False,
        inspect: Inspector[_T] | None = None,
    ) -> LintRun[_T]:
        """Lint one file; never raises for a bad file. ``full_composition``
        composes the whole stage for this file (no fast path); ``reads``
        records what the lint read (:class:`Reads`). ``inspect`` is handed
        the lint's Context and findings while the stage it linted (partly
        composed when the fast path applies) is open and the lint's cache
        active, so that a reader of the render data (``spec``) composes and
        resolves nothing twice; an inspector raising :class:`InspectionError`
        makes the file an error result."""
        trace = _Trace(reads)
        problem = unreadable_reason(path)
        if problem is not None:
            return trace.run(FileResult(path, status="error", error=f"{path}: {problem}"))
        try:
            return self._lint_file(path, trace, inspect, full_composition)
        except InspectionError as exc:
            return trace.run(FileResult(path, status="error", error=f"{path}: {exc}"))
        except (UnicodeDecodeError, CorruptValue, Tf.ErrorException, MemoryError) as exc:
            if out_of_memory(exc):
                return trace.run(_out_of_memory(path))
            return trace.run(FileResult(path, findings=(self._corrupt_finding(exc, path),)))

    def _corrupt_finding(self, exc: Exception, path: str) -> Finding:
        """The ST001 finding of a file found corrupt while it was linted
        (re-raises an exception that does not show that)."""
        message = _corrupt_file_message(exc, path)
        location = Location(path, None, os.path.abspath(path), None)
        severity = self._severity(STAGE_OPEN_FAILED_CODE, Severity.ERROR)
        return Finding(STAGE_OPEN_FAILED_CODE, STAGE_OPEN_FAILED_NAME, severity, message, location)

    def run_stage(
        self,
        stage: Usd.Stage,
        file: str | None = None,
        *,
        texts: Mapping[str, str] | None = None,
        prims: Sequence[Usd.Prim] | None = None,
        reads: bool = False,
        composition_errors: Callable[[], list] | None = None,
    ) -> LintRun[Any]:
        """Lint an open stage; ``file`` names it in findings (default: root
        layer). ``texts``: the text of layers with unsaved edits (an
        editor's), by real path, where their findings' lines are found
        instead of in their files. ``prims``: the usable prims the walk would
        keep (:meth:`walk_candidates`), in traversal order, so that there is
        no traversal (--variants knows them from the previous combination and
        what USD recomposed since); ``composition_errors``, likewise, gives the
        stage's composition errors (Context.composition_errors_source).
        ``reads``: as for :meth:`run_path`."""
        register_plugins()  # a host's stage too: raises SchemasMissing as a file's lint does
        trace = _Trace(reads)
        name = file or real_path(stage.GetRootLayer())
        try:
            findings, _ = self._lint(
                stage, file, trace, texts=texts, prims=prims, composition_errors=composition_errors
            )
        except (UnicodeDecodeError, CorruptValue, Tf.ErrorException, MemoryError) as exc:
            if out_of_memory(exc):
                return trace.run(_out_of_memory(name))
            # A layer read only for a value (a clip's manifest) is corrupt: as run_path says.
            return trace.run(FileResult(name, findings=(self._corrupt_finding(exc, name),)))
        return trace.run(FileResult(name, findings=tuple(findings)), "full", completed=True)

    def _lint_file(
        self, path: str, trace: _Trace, inspect: Inspector[_T] | None, full_composition: bool
    ) -> LintRun[_T]:
        register_plugins()  # not in the first file's open: engine/plugins.py
        problem = unsafe_to_open(path)
        if problem is not None:
            raise CorruptValue(problem)
        masked = None if full_composition or self.full_composition else self._open_partial(path)
        if masked is not None:
            run = self._lint_masked(path, masked, trace, inspect)
            if run is not None:
                return run
        opened = open_stage(path)
        if opened.stage is None and out_of_memory(opened.errors):
            raise OutOfMemory  # the process's memory, not the file (run_path)
        if opened.stage is None:
            return trace.run(
                FileResult(path, findings=tuple(self._open_failure_findings(path, opened)))
            )
        checked = masked.checked if masked is not None else frozenset()
        self._refuse_corrupt_crates(opened.stage, checked, full_composition)
        # The engine's own stage: the walk may ask USD for the typed prims (typed_prims.py).
        findings, value = self._lint(opened.stage, path, trace, inspect=inspect, own_stage=True)
        return trace.run(FileResult(path, findings=tuple(findings)), "full", True, value)

    def _lint_masked(
        self,
        path: str,
        masked: partial.PartialStage,
        trace: _Trace,
        inspect: Inspector[_T] | None,
    ) -> LintRun[_T] | None:
        """The lint of the fast path's stage; None when the whole stage must
        be composed (there is none, or a rule reads the whole scene)."""
        if trace.reads is not None:
            # What the fast path read decided how the stage is composed.
            trace.reads.add_layers(masked.layers)
            for anchor, asset_path in masked.missing:
                trace.reads.add_target(anchor, asset_path)
        if masked.corrupt is not None:
            raise CorruptValue(masked.corrupt)
        if masked.stage is None:
            return None
        try:
            findings, value = self._lint(masked.stage, path, trace, masked=True, inspect=inspect)
        except FullStageRequired:
            trace.forget()  # the whole stage is linted next
            return None
        return trace.run(FileResult(path, findings=tuple(findings)), "partial", True, value)

    def _refuse_corrupt_crates(
        self, stage: Usd.Stage, checked: frozenset[str], full_composition: bool
    ) -> None:
        """Raise CorruptValue for a used crate layer holding a spec USD cannot
        read (reading it crashes: no rule runs on such a file). ``checked``:
        the layers the fast path already walked. The retry after a crash
        (``full_composition``) walks every spec as well (partial.crate_problem)."""
        for layer in stage.GetUsedLayers():
            if layer_identifier(layer) not in checked:
                problem = partial.crate_problem(layer, walk=full_composition)
                if problem is not None:
                    raise CorruptValue(problem)

    def walk_candidates(
        self, stage: Usd.Stage, prims: Iterable[Usd.Prim] | None = None, own_stage: bool = False
    ) -> list[Usd.Prim]:
        """The usable prims of ``stage`` (or of ``prims``, some of them in
        traversal order) that the walk keeps: of a type the rules or the render
        prim lists want or that no schema defines, or with customData
        suppressions. On ``own_stage`` USD may find them (typed_prims.py)."""
        wants = self._dispatch.wants
        may_suppress = suppress.layers_may_suppress(stage.GetUsedLayers())
        if prims is None:
            if own_stage and not may_suppress:
                found = typed_prims.find(stage, wants, self._dispatch.unknown_type_names)
                if found is not None:
                    return found
            prims = stage.Traverse()
        type_name_of = Usd.Prim.GetTypeName  # unbound: see _walk
        if may_suppress:
            has = suppress.has_suppressions
            return [p for p in prims if wants(type_name_of(p)) or has(p)]
        return [p for p in prims if wants(type_name_of(p))]

    def _open_partial(self, path: str) -> partial.PartialStage | None:
        try:
            return partial.open_partial(path, self._dispatch.wants)
        except Exception:  # noqa: BLE001 - an optimisation must never cost a file
            if self.raise_errors:
                raise
            return None

    def _lint(
        self,
        stage: Usd.Stage,
        file: str | None,
        trace: _Trace,
        masked: bool = False,
        inspect: Inspector[_T] | None = None,
        own_stage: bool = False,
        texts: Mapping[str, str] | None = None,
        prims: Sequence[Usd.Prim] | None = None,
        composition_errors: Callable[[], list] | None = None,
    ) -> tuple[list[Finding], _T | None]:
        file = file or real_path(stage.GetRootLayer())
        ctx = Context(
            stage=stage,
            file=file,
            time_sample_cap=self.time_sample_cap,
            partial=masked,
            composition_errors_source=composition_errors,
        )
        used = stage.GetUsedLayers()
        # Each layer's file is asked once for all the words the lint looks for.
        held = layer_words.words_layers_may_hold(used, _LINT_WORDS)
        # Without value clips, a prim's authored property names say which of
        # its attributes can hold a value (resolve.PrimValues.has_value).
        ctx.cache.without_clips = "clips" not in held
        # Without either field anywhere, no spec is asked for its time samples or spline.
        ctx.cache.without_varying = not held.intersection(("timeSamples", "spline"))
        findings: list[Finding] = []
        value = None
        # Nothing edits the stage while rules run, so the helpers may cache.
        with Tf.DiagnosticTrap() as trap, lint_cache(ctx.cache):
            if texts:
                from ..layers.usda_text import hold_text

                for layer_path, text in texts.items():
                    hold_text(layer_path, text)
            try:
                may_suppress = suppress.SUPPRESSION_WORD in held
                work, suppressing = self._walk(stage, ctx, own_stage, prims, may_suppress)
                know_usable(stage, (prim for prim, _ in work))
                run = self._run
                with _read_only(used):
                    # A renderer rule runs only where some configuration is its renderer's.
                    present = self._decide_profiles(ctx)
                    run(_present(self._stage_rules, present), None, ctx, trace, findings)
                    # Each type's rules whose profile is present, chosen once per lint
                    # (by the tuple's id: ``work`` holds every tuple until the loop ends).
                    chosen: dict[int, tuple[Rule, ...]] = {}
                    for prim, rules in work:
                        kept = chosen.get(id(rules))
                        if kept is None:
                            kept = chosen[id(rules)] = _present(rules, present)
                        run(kept, prim, ctx, trace, findings)
                if may_suppress:  # else no prim silences a finding or holds an unused entry
                    findings = self._apply_data_suppressions(ctx, trace, findings, suppressing)
                findings = sorted(set(findings), key=Finding.sort_key)
                if inspect is not None:
                    value = inspect(ctx, findings)
            finally:
                trap.Clear()
                forget_prim_answers(ctx.cache)  # no reference cycle outlives the lint
        if trace.reads is not None:
            _record(trace.reads, stage, ctx, masked)
        return findings, value

    def _decide_profiles(self, ctx: Context) -> set[str]:
        """Decide the profile of every configuration (once per lint) and
        return the profiles present. Deciding reads the render prims'
        properties: a crate value found corrupt there is the file's problem
        (ST001), as in a rule."""
        if self.profiler is None:
            return set()
        try:
            ctx.profiles = self.profiler(ctx)
            return set(ctx.profiles.present())
        except Tf.ErrorException as exc:
            corrupt = corruption(exc, ctx.file)
            if corrupt is not None:
                raise CorruptValue(corrupt) from exc
            raise

    def _apply_data_suppressions(
        self, ctx: Context, trace: _Trace, findings: list[Finding], suppressing: list[Usd.Prim]
    ) -> list[Finding]:
        """Drop findings silenced in customData; report unused suppressions."""
        # A rule that raised lost its findings: whether it uses a suppression is unknown.
        failed = {trace.origin_code(f) for f in findings if f.code == INTERNAL_ERROR_CODE}
        kept, unused = suppress.apply_data_suppressions(
            ctx.stage,
            findings,
            self.rules,
            self.known_rules,
            suppressing=suppressing,
            failed=failed,
        )
        for rule in self.rules:
            if rule.code == suppress.UNUSED_SUPPRESSION_CODE:
                made = (self._finding(rule, diagnostic, ctx, trace) for diagnostic in unused)
                kept.extend(f for f in made if f is not None)
        return kept

    # -- internals ------------------------------------------------------------

    def _walk(
        self,
        stage: Usd.Stage,
        ctx: Context,
        own_stage: bool,
        prims: Iterable[Usd.Prim] | None,
        may_suppress: bool,
    ) -> tuple[list[tuple[Usd.Prim, tuple[Rule, ...]]], list[Usd.Prim]]:
        """One traversal of usable prims (or of ``prims``, the caller's
        :meth:`walk_candidates`): collect render prims, the prim work and the
        prims with customData suppressions (no second traversal for those).
        ``may_suppress``: whether a used layer's file may hold a suppression
        (reading every prim's customData costs more than the rest of the walk)."""
        work = []
        suppressing = []
        unknown = self._dispatch.unknown_type_names
        has_suppressions = suppress.has_suppressions if may_suppress else None
        if prims is None and own_stage and not may_suppress:
            # Then only the typed prims matter, and USD finds them without a Python walk.
            prims = typed_prims.find(stage, self._dispatch.wants, unknown)
        # Unbound: a method read from a prim passes Usd.Object.__getattribute__'s
        # validity check, which costs more than the call (the walk's prims are valid).
        type_name_of = Usd.Prim.GetTypeName
        lookup = self._dispatch.lookup
        # Per type name: its rules, the render prim lists its prims join and
        # whether no schema defines it, found at its first prim (hashing a
        # render schema's Tf.Type is a binding call: once a type name, not a prim).
        seen: dict[str, tuple[tuple[Rule, ...], list[list[Usd.Prim]], bool]] = {}
        # The type names nothing wants (most of a shot's prims: meshes, xforms),
        # skipped at the cost of a set lookup.
        unwanted: set[str] = set()
        for prim in stage.Traverse() if prims is None else prims:
            if has_suppressions is not None and has_suppressions(prim):
                suppressing.append(prim)
            type_name = type_name_of(prim)
            if type_name in unwanted:
                continue
            entry = seen.get(type_name)
            if entry is None:
                rules, kinds = lookup(type_name)
                if not (rules or kinds or type_name in unknown):
                    unwanted.add(type_name)
                    continue
                lists = [ctx.render_prims.setdefault(kind, []) for kind in kinds]
                entry = seen[type_name] = (rules, lists, type_name in unknown)
            rules, lists, is_unknown = entry
            for found in lists:
                found.append(prim)
            if rules:
                work.append((prim, rules))
            if is_unknown:
                ctx.unknown_type_prims.append(prim)
        return work, suppressing

    def _run(
        self,
        rules: Sequence[Rule],
        prim: Usd.Prim | None,
        ctx: Context,
        trace: _Trace,
        findings: list[Finding],
    ) -> None:
        """Run the ``rules`` (those whose profile is present: :func:`_present`) on
        ``prim`` (``check_prim``), or on the stage for None (``check_stage``),
        adding their findings to ``findings``. One call per prim, not per
        hook: a CI gate shot makes about 460 hook calls, most yielding nothing."""
        # Where the hook's findings start: moved on only after a hook added some.
        start = len(findings)
        for rule in rules:
            made = None
            try:
                made = rule.check_stage(ctx) if prim is None else rule.check_prim(prim, ctx)
                for diagnostic in made or ():
                    finding = self._finding(rule, diagnostic, ctx, trace)
                    if finding is not None:
                        findings.append(finding)
            except (FullStageRequired, UnicodeDecodeError, CorruptValue):
                raise  # a corrupt name is the file's problem, not the rule's (see lint_path)
            # SystemExit too: a rule's (or its library's) sys.exit() must not end the
            # run with its status and no report; and a KeyboardInterrupt or
            # GeneratorExit it raised itself (see _raised_by_rule).
            except (Exception, SystemExit, KeyboardInterrupt, GeneratorExit) as exc:
                if not _raised_by_rule(exc):
                    raise
                if out_of_memory(exc):  # no fault of the rule's: the file's lint fails
                    raise OutOfMemory from exc
                del findings[start:]  # the hook's other findings are lost
                if isinstance(exc, TypeError) and not isinstance(made, Iterable | None):
                    # `return Diagnostic(...)`: asked here, not of every hook's result
                    exc = MalformedDiagnostic(
                        f"returned {type(made).__name__} {made!r:.60}, not an iterable of "
                        "Diagnostics (a hook yields them)"
                    )
                findings.append(self._rule_error(rule, ctx, exc, ctx if prim is None else prim))
            if len(findings) > start:  # a finding is rare next to a hook call
                origin = (rule.code, None if prim is None else prim.GetPath())
                for finding in findings[start:]:
                    trace.origins.setdefault(finding, origin)
                start = len(findings)

    def _rule_error(
        self, rule: Rule, ctx: Context, exc: BaseException, target: Usd.Prim | Context
    ) -> Finding:
        """The internal-error finding for a hook that raised on ``target``
        (a prim or the Context), unless the error must propagate."""
        if isinstance(exc, Tf.ErrorException):
            corrupt = corruption(exc, ctx.file)
            if corrupt is not None:  # a crate value USD unpacks only when a rule reads it
                raise CorruptValue(corrupt) from exc
        if self.raise_errors:
            raise exc
        prim_path = target.GetPath() if isinstance(target, Usd.Prim) else None
        where = f" on {prim_path}" if prim_path is not None else ""
        debug.show(exc, f"{ctx.file}: rule {rule.code} raised (UL000){where}")
        detail = " ".join(str(exc).split())  # USD's errors span lines; findings do not
        # A plugin's rule is its authors' to fix: name its package.
        package = type(rule).__module__.partition(".")[0]
        to = "" if package == __name__.partition(".")[0] else f" to the authors of {package}"
        if isinstance(exc, MalformedDiagnostic):
            # Where the engine noticed is no help: the rule is what needs fixing.
            message = (
                f"rule {rule.code} ({rule.name}) {detail}{where}; its other findings on "
                f"this file are lost. Please report this{to}."
            )
        else:
            import traceback  # only for a rule that raised (it imports textwrap)

            frame = traceback.extract_tb(exc.__traceback__)[-1]
            message = (
                f"rule {rule.code} ({rule.name}) raised {type(exc).__name__}"
                f"{': ' + detail if detail else ''}{where} "
                f"[{os.path.basename(frame.filename)}:{frame.lineno}]; its other findings on "
                f"this file are lost. Please report this{to}."
            )
        return Finding(
            INTERNAL_ERROR_CODE,
            INTERNAL_ERROR_NAME,
            Severity.ERROR,
            message,
            Location(ctx.file, str(prim_path) if prim_path is not None else None),
        )

    def _severity(self, code: str, default: Severity) -> Severity:
        return self.severities.get(code, default)

    def _finding(
        self, rule: Rule, diagnostic: Diagnostic, ctx: Context, trace: _Trace
    ) -> Finding | None:
        """The finding of a diagnostic, judged under its configuration's
        profile (None when that profile switches the rule off there)."""
        problem = malformed(diagnostic)
        if problem is not None:
            raise MalformedDiagnostic(problem)
        severity, profile, reason = rule.severity, None, None
        if ctx.profiles is not None:
            verdict = ctx.profiles.judge(rule.code, rule.severity, rule.profile, diagnostic.at)
            if verdict is None:
                return None
            choice, severity = verdict
            profile, reason = choice.name, choice.reason
        finding = Finding(
            code=rule.code,
            name=rule.name,
            # A severity the user configured wins over the profile's.
            severity=self._severity(rule.code, severity),
            message=bounded_message(diagnostic.message),
            location=locate(ctx.stage, ctx.file, diagnostic.at, diagnostic.layer),
            fix=_fix_info(diagnostic.fix),
            profile=profile,
            profile_reason=reason,
        )
        if diagnostic.fix is not None:
            trace.fixes.setdefault(finding, diagnostic.fix)
        return finding

    def _open_failure_findings(self, path: str, opened: StageOpenResult) -> Iterable[Finding]:
        # Not selectable away: a file that cannot be opened is never a silent pass.
        severity = self._severity(STAGE_OPEN_FAILED_CODE, Severity.ERROR)
        return open_failure_findings(path, opened.errors, severity)


def _present(rules: Sequence[Rule], present: set[str]) -> tuple[Rule, ...]:
    """The ``rules`` whose profile is ``present`` (or that have none): a renderer's
    rule runs only where some configuration is its renderer's."""
    return tuple(r for r in rules if r.profile is None or r.profile in present)


@contextmanager
def _read_only(layers: Iterable[Sdf.Layer]) -> Iterator[None]:
    """No edit of ``layers`` while rules run: a hook that edits the stage raises
    (its UL000), so the edit never reaches a later rule, a fix that saves the
    layer (``--fix``, a ValidationFixer) or the caller's stage (lint_stage)."""
    editable = [layer for layer in layers if layer.permissionToEdit]
    for layer in editable:
        layer.SetPermissionToEdit(False)
    try:
        yield
    finally:
        for layer in editable:
            layer.SetPermissionToEdit(True)


def _out_of_memory(path: str) -> FileResult:
    """The result of a file whose lint ran out of memory: an error (the tool
    could not lint it, exit 2), never stored by the result cache."""
    return FileResult(path, status="error", error=f"{path}: {out_of_memory_message()}")


def unsafe_to_open(path: str) -> str | None:
    """Why USD must not read the file at ``path`` (one line), or None: a
    corrupt crate's counts cost minutes and GBs, a text layer nesting 100,000
    levels overflows USD's parser. A text layer's bytes are read once for
    this and for the questions layer_words answers later in the lint."""
    text = layer_words.text_bytes(path)
    if text is not None:
        return nesting_problem(path, text)
    return crate_structure_problem(path) or nesting_problem(path)


def _record(reads: Reads, stage: Usd.Stage, ctx: Context, masked: bool) -> None:
    """What the lint of ``stage`` read, into ``reads``."""
    used = stage.GetUsedLayers(includeClipLayers=True)
    reads.add_layers(used)
    reads.context = resolver_context_key(stage.GetPathResolverContext())
    for anchor, value in ctx.asset_dependencies:
        reads.add_asset(anchor, value)
    # A stage composed without errors resolved every arc it composed; with
    # errors, its layers' arcs are listed to find the assets that are missing.
    # (The fast path lists the arcs of every layer it reaches: PartialStage.missing.)
    if not masked and ctx.composition_errors:
        reads.add_arc_targets(used)
    if layer_words.layers_may_hold(used, "clips"):
        reads.add_clips(stage)


def _corrupt_file_message(exc: Exception, path: str) -> str:
    """Why ``path`` cannot be checked, for an exception that shows it is
    corrupt; re-raises any other."""
    if isinstance(exc, UnicodeDecodeError):
        # A corrupt crate can hold names that are not UTF-8: USD composes
        # them, but every Python read of them raises.
        byte = exc.object[exc.start : exc.start + 1].hex()
        return (
            f"the file holds a name or string that is not valid UTF-8 (byte 0x{byte}); "
            "USD reads it, but nothing in it can be checked: the file is probably corrupt"
        )
    if isinstance(exc, CorruptValue):
        return str(exc)
    # A Tf.ErrorException outside a rule (the walk, suppressions, locating a finding).
    found = corruption(exc, path) if isinstance(exc, Tf.ErrorException) else None
    if found is None:
        raise exc
    return found


def open_failure_findings(
    path: str,
    errors: Sequence[str],
    severity: Severity,
    texts: Mapping[str, str] | None = None,
) -> list[Finding]:
    """The ST001 findings of USD's error lines about a layer of ``path`` it cannot
    read (a file's open, an editor's text), each placed where the line says.
    ``texts``: the text of layers with unsaved edits, by real path (their columns
    are counted in it, not in the file)."""
    # USD follows the real cause with a generic "Failed to open layer @f@": say it once.
    chosen = [line for line in errors if not line.startswith("Failed to open layer")] or errors
    # Its parser also says some errors twice, once with ``file:line:col:`` in front.
    placed = {without_position(line) for line in chosen if position_from_error(line)}
    return [
        Finding(
            STAGE_OPEN_FAILED_CODE,
            STAGE_OPEN_FAILED_NAME,
            severity,
            without_position(line),
            _error_location(path, line, texts or {}),
        )
        for line in chosen
        if line not in placed
    ]


def _error_location(path: str, message: str, texts: Mapping[str, str]) -> Location:
    """Where USD's error points: the layer and line (and column) it names, a
    sublayer's own when the error is in one; else the file itself."""
    position = position_from_error(message)
    if position is None:
        return Location(path, None, os.path.abspath(path), None)
    layer, line, column = position
    if not os.path.isfile(layer) and layer not in texts:
        layer = path
    layer = single_root(os.path.abspath(layer))
    if column is not None:
        column = _character_column(texts.get(layer), layer, line, column)
    return Location(path, None, layer, line, column)


def _character_column(text: str | None, layer: str, line: int, column: int) -> int:
    """USD's parser counts a column in bytes (PEGTL's position, byte_in_line + 1:
    pxr/base/tf/pxrPEGTL/pegtl.h); a finding's column counts characters, as an
    editor and a report mark them (past an "é", bytes are more). Unchanged when
    the line cannot be read."""
    from ..layers.source_lines import read_lines  # a parse error's only

    lines = text.split("\n") if text is not None else read_lines(layer)
    if lines is None or not 0 < line <= len(lines):
        return column
    before = lines[line - 1].encode("utf-8", "surrogatepass")[: max(column - 1, 0)]
    return len(before.decode("utf-8", "ignore")) + 1


def _overrides(rule: Rule, hook: str) -> bool:
    """True unless ``rule``'s hook is the base class's, which yields nothing."""
    return getattr(getattr(rule, hook), "__func__", None) is not getattr(Rule, hook)


def _fix_info(fix: Fix | None) -> FixInfo | None:
    return None if fix is None else FixInfo(fix.description, fix.safe)


def _raised_by_rule(exc: BaseException) -> bool:
    """Whether a hook's ``exc`` is the rule's fault (its UL000), not the user's
    Ctrl-C. The command turns Ctrl-C into its own Stopped (never caught here) and
    a worker ignores it, so a KeyboardInterrupt there is a rule's (a plugin's
    ``raise KeyboardInterrupt`` ended a run with click's "Aborted!", exit 1, no
    report); in a Python program whose SIGINT raises it, it may be the user's."""
    import signal

    return not isinstance(exc, KeyboardInterrupt) or (
        signal.getsignal(signal.SIGINT) is not signal.default_int_handler
    )
