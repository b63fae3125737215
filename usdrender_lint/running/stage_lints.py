"""Linting stages that a host application opened (UsdValidation, NVIDIA's
Asset Validator): each stage linted once per state, by a linter built as
``check`` builds it for that file.

A host calls one validator (or rule) per usdrender-lint rule, but the rules
share a per-stage Context, the engine's customData suppressions and the
profile decision, so the first call on a stage lints it with every rule and
the others read that lint. The lint is dropped when the stage changes.

Every cache here holds its stages weakly (:class:`StageMap`): a stage kept
alive by a cache keeps its layers open, and USD then hands them, as they were
read, to the next stage opened on the same file (``Sdf.Layer.FindOrOpen``
reads no file whose layer is open), so a host validating a file again after
it changed on disk would get the old answer.
"""

from __future__ import annotations

import os
import threading
import time
import weakref
from collections.abc import Callable, Hashable, Iterator, MutableMapping
from dataclasses import field, replace
from typing import TYPE_CHECKING, Any, TypeVar

from pxr import Tf, Usd

from ..config import Stamps, config_candidates, file_stamps, stamped_read, stamps_hold
from ..engine import Linter, TracedFinding
from ..model import FileResult, Finding, Report
from ..records import record

if TYPE_CHECKING:
    from ..engine.variants import VariantExplorer

#: Stages whose lint is kept (the most recently linted ones).
MAX_CACHED_STAGES = 4
#: Seconds a configuration that cannot be read is not read again while the files
#: the search looks at are unchanged: a file it extends is not among them, so an
#: edit there is seen by the first validation that starts after this.
FAILURE_SECONDS = 1.0

_V = TypeVar("_V")


class StageMap(MutableMapping[Usd.Stage, _V]):
    """A value per stage for at most MAX_CACHED_STAGES stages (the oldest
    entry goes first), holding no stage alive: an entry goes when its stage
    is closed. (A stage's Python object lives as long as the stage does, so a
    stage is the same key on every call.)"""

    def __init__(self) -> None:
        self._entries: weakref.WeakKeyDictionary[Usd.Stage, _V] = weakref.WeakKeyDictionary()

    def __getitem__(self, stage: Usd.Stage) -> _V:
        return self._entries[stage]

    def __setitem__(self, stage: Usd.Stage, value: _V) -> None:
        self._entries[stage] = value
        while len(self._entries) > MAX_CACHED_STAGES:
            del self._entries[next(iter(self._entries))]

    def __delitem__(self, stage: Usd.Stage) -> None:
        del self._entries[stage]

    def __iter__(self) -> Iterator[Usd.Stage]:
        return iter(self._entries)

    def __len__(self) -> int:
        return len(self._entries)


@record
class _StageLint:
    """One stage's traced findings, valid until the stage changes or its
    linter does (its configuration was read again)."""

    findings: list[TracedFinding]
    linter: Linter
    listener: Any = field(default=None, repr=False)


class StageLints:
    """Traced findings per stage, computed once per stage state, thread-safe
    (UsdValidation may call validators from worker threads).

    ``linter_for`` gives the linter for a stage (built once per linter key);
    ``lint_for``, when given, what lints it (the linter, or ``check``'s
    variant explorer when the configuration sets ``variants``)."""

    def __init__(
        self,
        linter_for: Callable[[Usd.Stage], Linter],
        lint_for: Callable[[Usd.Stage], Linter | VariantExplorer] | None = None,
    ) -> None:
        self._linter_for = linter_for
        self._lint_for = lint_for or linter_for
        self._lints: StageMap[_StageLint] = StageMap()
        self._lock = threading.RLock()

    def findings(self, stage: Usd.Stage, linter: Linter | None = None) -> list[TracedFinding]:
        """``linter``: the stage's linter when the caller has it (default: asked
        of ``linter_for``, which reads the configuration's stamps)."""
        if linter is None:
            linter = self._linter_for(stage)
        with self._lock:
            cached = self._lints.get(stage)
            # A host validates its open stage again after its user edited the
            # configuration: the stage is unchanged, the linter is another.
            if cached is not None and cached.linter is not linter:
                self._drop(stage)
                cached = None
            if cached is None:
                # The edit that invalidates comes from anywhere: USD tells us.
                listener = Tf.Notice.Register(Usd.Notice.ObjectsChanged, self._forget, stage)
                traced = self._lint_for(stage).run_stage(stage, stage_file(stage)).traced()
                cached = _StageLint(traced, linter, listener)
                while len(self._lints) >= MAX_CACHED_STAGES:
                    self._drop(next(iter(self._lints)))
                self._lints[stage] = cached
            return cached.findings

    def linter(self, stage: Usd.Stage) -> Linter:
        return self._linter_for(stage)

    def _forget(self, notice: Usd.Notice.ObjectsChanged, stage: Usd.Stage) -> None:
        with self._lock:
            self._drop(stage)

    def _drop(self, stage: Usd.Stage) -> None:
        cached = self._lints.pop(stage, None)
        if cached is not None and cached.listener is not None:
            cached.listener.Revoke()


class FirstFailures:
    """Stages whose lint failed and was reported: a failure (a configuration
    that cannot be read) is one issue per validation of a stage, as check says
    it once, not one per validator. A validation asks once per validator task
    (``asker``: the validator and the prim it is called for); a host that
    validates a stage it keeps open again asks again, which begins another
    validation that reports it too. Thread-safe."""

    def __init__(self) -> None:
        #: Each stage's askers since its failure was last reported.
        self._asked: StageMap[set[Hashable]] = StageMap()
        self._lock = threading.Lock()

    def first(self, stage: Usd.Stage, asker: Hashable) -> bool:
        """Whether the stage's failure is ``asker``'s to report: the first to
        ask in this validation of it (and then it has)."""
        with self._lock:
            asked = self._asked.get(stage)
            if asked is None or asker in asked:
                self._asked[stage] = {asker}
                return True
            asked.add(asker)
            return False


def _linter_of(prepared: Any) -> Linter:
    linter = prepared.linter
    assert isinstance(linter, Linter)  # a Prepared's linter: never an explorer
    return linter


def stage_file(stage: Usd.Stage) -> str:
    """How findings name the stage: its root layer's file, else its identifier."""
    root = stage.GetRootLayer()
    return root.realPath or root.identifier


class CheckLinters:
    """The linter ``check`` would use for a stage's file: the configuration
    found from its folder (as ``check`` finds it), so the same rules, options
    and renderer profiles (``auto`` infers each stage's from its settings).
    One linter per folder, read again when a configuration file it read (the
    one found or one it extends) changed, or one appeared where the search
    looks (a folder that had none, or nearer), as the language server reads it
    (running/documents.py): a host keeps running while its user edits the
    configuration. Per-path ignores applied as ``check`` applies them."""

    def __init__(self) -> None:
        #: Each folder's Prepared, with the state of the files it read (config.file_state).
        self._prepared: dict[str, tuple[Any, Stamps]] = {}
        #: Each folder's failure to prepare, with the state of the files the search
        #: looked at and when (time.monotonic) it failed.
        self._failed: dict[str, tuple[Exception, Stamps, float]] = {}
        #: Each stage's force-exclude answer, with the Prepared it was judged by.
        self._force_excluded: StageMap[tuple[Any, bool]] = StageMap()
        self._lock = threading.Lock()

    def prepared(self, stage: Usd.Stage) -> Any:
        """The pipeline's Prepared for the stage's file (raises RequestError)."""
        from .pipeline import Request, RequestError, prepare

        file = stage_file(stage)
        folder = os.path.dirname(file) if os.path.isabs(file) else os.getcwd()
        # Compared outside the lock: validators called from several threads
        # would else wait on each other's stats.
        cached = self._prepared.get(folder)
        if cached is not None and stamps_hold(cached[1]):
            return cached[0]
        with self._lock:
            cached = self._prepared.get(folder)  # another thread's, meanwhile
            if cached is not None and stamps_hold(cached[1]):
                return cached[0]
            failed = self._failed.get(folder)
            if (
                failed is not None
                and time.monotonic() - failed[2] < FAILURE_SECONDS
                and stamps_hold(failed[1])
            ):
                # A new exception: one raised again gathers every raise's frames.
                raise type(failed[0])(*failed[0].args) from None
            request = Request((file,), jobs=1, timeout=None, progress=False)
            # The files it read and those the search looked at: a configuration
            # created later (where there was none, or nearer) is read too.
            candidates = config_candidates(file)
            before = file_stamps(candidates)  # before the read, should it fail
            try:
                prepared, stamps = stamped_read(
                    candidates, lambda: prepare(request), lambda p: p.settings.sources
                )
            except RequestError as exc:
                # Every validator's call on every prim would read it to fail again.
                self._prepared.pop(folder, None)
                self._failed[folder] = (exc, before, time.monotonic())
                raise
            self._failed.pop(folder, None)
            self._prepared[folder] = (prepared, stamps)
            return prepared

    def linter(self, stage: Usd.Stage) -> Linter:
        return _linter_of(self.prepared(stage))

    def lint(self, stage: Usd.Stage) -> Linter | VariantExplorer:
        """What lints the stage as ``check`` lints its file: with ``variants``
        set, under each variant combination. The explorer authors each
        combination in the session layer and empties it after, so a stage
        whose session layer holds opinions (a host's live stage) is linted
        under its selections only, as composed now."""
        prepared = self.prepared(stage)  # once: each call checks the configuration's stamps
        linter = _linter_of(prepared)
        spec = prepared.spec
        if spec.variant_combinations is None or not stage.GetSessionLayer().empty:
            return linter
        from ..engine.variants import VariantExplorer

        return VariantExplorer(linter, spec.variant_combinations)

    def fixable(self, stage: Usd.Stage, finding: Finding) -> bool:
        """Whether ``check --fix`` may fix the finding: not a rule the
        configuration's ``unfixable`` names (as Prepared.is_reported judges),
        nor under a configuration that sets ``variants``, which ``check --fix``
        refuses (pipeline._check_fix_request): its fixes would be made under the
        current selections only."""
        prepared = self.prepared(stage)
        return not prepared.settings.variants and finding.code not in prepared.unfixable

    def force_excluded(self, stage: Usd.Stage, prepared: Any = None) -> bool:
        """Whether ``check`` leaves the stage's file out though it is given by
        name (``force-exclude`` with a pattern that matches it): then it
        reports nothing on it. ``prepared``: the stage's, when the caller has it."""
        from .discovery import Exclusions, force_excluded
        from .pipeline import folder_exclusions

        if prepared is None:
            prepared = self.prepared(stage)
        if not prepared.settings.force_exclude:
            return False
        # Every checker asks, and the answer walks the folders (.gitignore): once
        # per stage (a host validates a new one each time) and preparation.
        known = self._force_excluded.get(stage)
        if known is not None and known[0] is prepared:
            return known[1]
        exclusions = Exclusions.of(prepared.settings)
        answer = force_excluded(stage_file(stage), exclusions, folder_exclusions(prepared))
        with self._lock:
            self._force_excluded[stage] = (prepared, answer)
        return answer

    def excluded(self, stage: Usd.Stage) -> Callable[[str], bool]:
        """Whether ``check`` leaves a layer's path out of linting (exclude,
        .gitignore): its fixes leave such a layer alone (FixOptions.excluded)."""
        from .pipeline import excluded_from_linting

        return excluded_from_linting(self.prepared(stage))

    def reported(
        self, stage: Usd.Stage, traced: list[TracedFinding], prepared: Any = None
    ) -> list[TracedFinding]:
        """The findings ``check`` reports (per-path ignores applied), each as
        ``check`` reports it (no fix of an ``unfixable`` rule's finding).
        ``prepared``: the stage's, when the caller has it."""
        file = stage_file(stage)
        if prepared is None:
            prepared = self.prepared(stage)
        finished = prepared.finish(
            Report((FileResult(file, findings=tuple(t.finding for t in traced)),))
        ).findings
        # finish drops fixes: a finding is known by the rest of it.
        kept = {replace(f, fix=None): f for f in finished}
        reported = []
        for t in traced:
            shown = kept.get(replace(t.finding, fix=None))
            if shown is not None:
                reported.append(t if shown is t.finding else replace(t, finding=shown))
        return reported


class CheckedLints:
    """The findings ``check`` reports on a stage, shared by every validator or
    checker a host calls: one lint per stage state with ``check``'s linter for
    its file, per-path ignores applied (once per lint, not once per call), none
    on a file ``force-exclude`` leaves out."""

    def __init__(self) -> None:
        self.checks = CheckLinters()
        self.lints = StageLints(self.checks.linter, self.checks.lint)
        self.failures = FirstFailures()
        self._reported: StageMap[tuple[list[TracedFinding], list[TracedFinding]]] = StageMap()
        self._lock = threading.Lock()

    def reported(self, stage: Usd.Stage) -> list[TracedFinding]:
        """Raises RequestError when the stage's configuration cannot be read."""
        # Once a call: a host calls once per validator and prim, and each look
        # at the configuration stats every file its search reads.
        prepared = self.checks.prepared(stage)
        if self.checks.force_excluded(stage, prepared):
            return []
        traced = self.lints.findings(stage, _linter_of(prepared))
        with self._lock:
            cached = self._reported.get(stage)
        if cached is not None and cached[0] is traced:
            return cached[1]
        kept = self.checks.reported(stage, traced, prepared)
        with self._lock:
            self._reported[stage] = (traced, kept)
        return kept


__all__ = [
    "MAX_CACHED_STAGES",
    "CheckLinters",
    "CheckedLints",
    "FirstFailures",
    "StageLints",
    "StageMap",
    "stage_file",
]
