"""Fixing one stage: lint, apply fixes, check them, repeat.

A fix edits the layer that holds the strongest opinion behind its finding
(``Fix.layer`` when the rule names one; the root layer for stage metadata)
through ``Usd.EditContext``, and only a writable layer of the stage's own layer
stack: never a layer a reference or payload brings in. Safe fixes (conditional
ones are only offered when their condition holds) run by default, unsafe ones
on request.

Every fix is verified: its change must be expressible as a text edit of each
text layer it touches (:mod:`.sources`), and linting the stage again must no
longer report its finding; otherwise it is undone and reported as not applied,
with the reason. A round tries the fixes of objects that do not overlap
together (one commit, one lint to check them all); when that fails, they are
tried one at a time. The next round comes from the new lint, so a fix that
reveals another finding is handled and a second run changes nothing. At the end
the changed layers are written (:mod:`.writing`) or, for ``--diff``, shown as a
patch (:mod:`.diff`). :func:`usdrender_lint.fixing.fix_files` runs it per file.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Mapping
from dataclasses import field

from pxr import Sdf, Tf, Usd

from .. import debug
from ..api import Fix
from ..engine import Linter, LintRun, open_stage
from ..layers.files import layer_identifier, layer_real_path
from ..layers.writing import ChangedOnDisk, save_layer, save_text
from ..model import AppliedFix, FileResult, Finding
from ..paths import display_path
from ..records import record
from .diff import merged, patch
from .sources import Sources

#: Fixes tried on one stage at most, per fix the first lint offers, and never
#: fewer than MIN_ATTEMPTS (a chain of fixes that reveal new findings ends
#: there, with a note, as ruff stops after 100 passes that do not converge).
MAX_ATTEMPTS_PER_FIX = 10
MIN_ATTEMPTS = 100


class FixError(Exception):
    """The fixing cannot start (e.g. the --fix-to layer is unusable): one line."""


@record(frozen=True)
class FixOptions:
    #: Apply unsafe fixes too (--unsafe-fixes).
    unsafe: bool = False
    #: False for --diff: compute the edits, show them, write nothing.
    write: bool = True
    #: Write every fix as an override into this layer (--fix-to).
    fix_to: str | None = None
    #: The text of layers as an editor holds them, unsaved, by real path (the
    #: language server): fixes edit that text instead of the file's.
    texts: Mapping[str, str] | None = None
    #: With ``texts``: fixes edit those texts only; a fix of any other layer (a
    #: file the text composes) is not applied (``check -`` writes no file).
    texts_only: bool = False
    #: With ``write`` False: show the edit even where --fix may not write the
    #: file (read-only, hard links); the HTML report's diffs. --diff itself
    #: previews --fix, refusals included.
    any_file: bool = False
    #: Called before the first file is written (a worker's time limit stops there).
    before_writing: Callable[[], None] | None = None
    #: Whether a layer of the stack other than the root (its real path) is one the
    #: configuration leaves out of linting (exclude, .gitignore): fixes leave it alone.
    excluded: Callable[[str], bool] | None = None


@record
class FixRun:
    """What fixing a set of files did."""

    outcomes: list[AppliedFix] = field(default_factory=list)
    #: One unified diff per changed text layer (--diff).
    diffs: list[str] = field(default_factory=list)
    #: Each stage's edit of a text layer for --diff: (file, text as read, text
    #: as fixed, the file's name on the command line); :meth:`once_per_layer`.
    edits: list[tuple[str, str, str, str]] = field(default_factory=list)
    #: Lines for the user beside the report (e.g. a .usdc --diff cannot show).
    notes: list[str] = field(default_factory=list)
    #: Layers that could not be written (the run exits 2), one line each.
    errors: list[str] = field(default_factory=list)
    #: With --fix-to: the findings left on each stage with the overrides applied.
    remaining: list[FileResult] = field(default_factory=list)

    @property
    def applied(self) -> tuple[AppliedFix, ...]:
        return tuple(o for o in self.outcomes if o.applied)

    @property
    def unapplied(self) -> tuple[AppliedFix, ...]:
        return tuple(o for o in self.outcomes if not o.applied)

    def extend(self, other: FixRun) -> None:
        self.outcomes.extend(other.outcomes)
        self.diffs.extend(other.diffs)
        self.edits.extend(other.edits)
        self.notes.extend(other.notes)
        self.errors.extend(other.errors)
        self.remaining.extend(other.remaining)

    def once_per_layer(self) -> None:
        """--diff of several stages: stages sharing a layer each start from its
        file (nothing is written between them), so each shows the same fix of
        it, where --fix writes it after the first and the next finds nothing
        left to fix. One patch per layer and one fix per edit, as --fix applies
        them: the patch of a layer the stages edit differently holds all their
        edits (two patches of one file would not apply one after the other)."""
        by_file: dict[str, list[tuple[str, str, str, str]]] = {}
        for edit in self.edits:
            by_file.setdefault(edit[0], []).append(edit)
        diffs = []
        for file, edits in by_file.items():
            original, given = edits[0][1], edits[0][3]
            text = merged(original, [fixed for _, _, fixed, _ in edits])
            if text is None:  # edits of the same lines: each stage's patch
                diffs += [patch(file, old, new, given=name) for _, old, new, name in edits]
            else:
                diffs.append(patch(file, original, text, given=given))
        self.diffs[:] = list(dict.fromkeys(diffs if self.edits else self.diffs))
        seen: set[tuple] = set()
        kept = []
        for outcome in self.outcomes:
            same = (outcome.code, outcome.path, outcome.layer, outcome.description)
            if not outcome.applied or same not in seen:
                seen.add(same)
                kept.append(outcome)
        self.outcomes[:] = kept


@record
class Applied:
    """A fix applied (in memory) and what it changed on the stage."""

    finding: Finding
    fix: Fix
    layer: Sdf.Layer
    #: The stage paths the fix changed (resynced or changed info).
    paths: set[Sdf.Path]
    #: Its entry in :attr:`StageFixer.outcomes`.
    outcome: int


class StageFixer:
    """Fixes one stage. ``in_memory`` (for --fix-to) edits layers in memory only,
    any layer the stage uses, and keeps the stage for the caller."""

    def __init__(
        self,
        linter: Linter,
        path: str,
        options: FixOptions,
        keep: Callable[[Finding], bool],
        *,
        in_memory: bool = False,
        callers_stage: bool = False,
    ) -> None:
        self.linter = linter
        #: The stage is the caller's (a UsdValidation fixer, an Asset Validator
        #: Suggestion): at the end its session layer is kept and only the layers
        #: that were clean when fixing started are read back from their files.
        self.callers_stage = callers_stage
        self._clean_at_start: list[Sdf.Layer] = []
        self.path = path
        self.options = options
        self.keep = keep
        self.in_memory = in_memory
        self.result = FixRun()
        self.stage: Usd.Stage | None = None
        self.sources: Sources | None = None
        self.applied: list[Applied] = []
        #: The findings on the stage as the accepted fixes left it.
        self.findings: list[Finding] = []

    @property
    def outcomes(self) -> list[AppliedFix]:
        return self.result.outcomes

    def run(self, stage: Usd.Stage | None = None) -> None:
        """Fix the stage of the file (or ``stage``, opened by the caller)."""
        if stage is None:
            stage = open_stage(self.path).stage
            if stage is None:
                return  # nothing to fix; the report says why (ST001, a missing file, ...)
        self.stage = stage
        if self.callers_stage:
            self._clean_at_start = [
                layer
                for layer in stage.GetLayerStack(includeSessionLayers=False)
                if not layer.dirty
            ]
        # USD's own warnings (e.g. while exporting a spline) stay off the user's stderr.
        with Tf.DiagnosticTrap() as trap:
            try:
                self.sources = Sources(
                    self.stage,
                    in_memory=self.in_memory,
                    texts=self.options.texts,
                    texts_only=self.options.texts_only,
                    writing=self.options.write or not self.options.any_file,
                    excluded=self.options.excluded,
                )
                self.findings = self._attempts()
                if not self.in_memory:
                    self._finish()
            finally:
                if not self.in_memory:
                    self.close()
                trap.Clear()

    def close(self) -> None:
        """Forget the in-memory edits and the stage."""
        if self.callers_stage:
            # A fix tried and undone leaves its layer dirty with the same content.
            for layer in self._clean_at_start:
                if layer.dirty and os.path.isfile(layer_real_path(layer)):
                    layer.Reload(True)
        elif self.sources is not None:
            self.sources.discard()
        self.stage = None

    # -- fix by fix -----------------------------------------------------------------

    def _attempts(self) -> list[Finding]:
        """Fix until no fix is left to try: a round tries the fixes of objects
        that do not overlap together (one commit, one lint to check them all);
        a round that fails, and each fix of it, goes one fix at a time."""
        run = self.linter.run_stage(self.stage, self.path)
        tried: set[tuple] = set()
        alone: set[tuple] = set()  # fixes that must be tried one at a time
        budget = None
        while True:
            pairs = [(f, run.fix(f)) for f in run.findings]
            todo = [(f, x) for f, x in pairs if self._wanted(f, x) and _fix_key(f, x) not in tried]
            if budget is None:
                budget = limit = max(MIN_ATTEMPTS, MAX_ATTEMPTS_PER_FIX * len(todo))
            if todo and budget <= 0:
                codes = ", ".join(sorted({finding.code for finding, _ in todo}))
                self.result.notes.append(
                    f"{display_path(self.path)}: fixing stopped after {limit} fix attempts, "
                    f"as fixes kept revealing new findings (still offering a fix: {codes}); "
                    "the report shows what remains; a fix that does not converge is a bug "
                    "of its rule"
                )
            if not todo or budget <= 0:
                return list(run.findings)
            batch = self._round(todo, alone)
            if len(batch) > 1:
                after = self._together(batch)
                if after is not None:
                    tried.update(_fix_key(f, x) for f, x, _ in batch)
                    budget -= len(batch)
                    run = after
                    continue
                alone.update(_fix_key(f, x) for f, x, _ in batch)
            finding, fix, _ = batch[0]
            tried.add(_fix_key(finding, fix))
            budget -= 1
            after = self._one(finding, fix)
            if after is not None:
                run = after

    def _one(self, finding: Finding, fix: Fix) -> LintRun[None] | None:
        """Try one fix on its own and record its outcome; the lint after it, or
        None when it was not applied."""
        try:
            reason, after = self._alone(finding, fix)
        except Exception as exc:  # noqa: BLE001 - one fix must not cost the others
            debug.show(exc, f"internal error while fixing {finding.code}")
            reason, after = f"internal error while fixing: {type(exc).__name__}: {exc}", None
        self.outcomes.append(_outcome(finding, fix, self._shown_layer(finding, fix), reason))
        return after

    def _round(self, todo, alone: set[tuple]) -> list[tuple[Finding, Fix, Sdf.Layer | None]]:
        """The fixes to try together: the first fix, and the later ones that edit
        other objects (two fixes on one object, or a prim and its property, could
        undo each other) and may edit their layer."""
        batch: list[tuple[Finding, Fix, Sdf.Layer | None]] = []
        scopes = _Scopes()
        for finding, fix in todo:
            key = _fix_key(finding, fix)
            layer, problem = self._editable(finding, fix)
            if batch and (key in alone or problem is not None):
                continue
            scope = _scope(finding)
            if scopes.overlaps(scope):
                continue
            batch.append((finding, fix, layer))
            scopes.add(scope)
            if key in alone or problem is not None:
                break
        return batch

    def _together(self, batch) -> LintRun[None] | None:
        """Apply ``batch`` and check it as one; the lint after it, or None when
        anything failed (then everything is undone)."""
        assert self.stage is not None and self.sources is not None
        checkpoint = self.sources.checkpoint()
        touched: list[Sdf.Layer] = []
        done = []
        try:
            for finding, fix, layer in batch:
                changed, paths, failure = self._apply(fix, layer)
                touched.extend(layer for layer in changed if layer not in touched)
                if failure or self._also_edits(changed, layer):
                    self.sources.back_to(checkpoint, touched)
                    return None
                done.append(Applied(finding, fix, layer, paths, -1))
            if self.sources.commit(touched) is not None:
                self.sources.back_to(checkpoint, touched)
                return None
            after = self.linter.run_stage(self.stage, self.path)
        except Exception:  # noqa: BLE001 - tried again one at a time, where it is reported
            self.sources.back_to(checkpoint, touched)
            return None
        if any(_remains(a.finding, a.fix, after) for a in done):
            self.sources.back_to(checkpoint, touched)
            return None
        for applied in done:
            applied.outcome = len(self.outcomes)
            self.applied.append(applied)
            layer_shown = _layer_path(applied.layer)
            self.outcomes.append(_outcome(applied.finding, applied.fix, layer_shown, None))
        return after

    def _wanted(self, finding: Finding, fix: Fix | None) -> bool:
        return (
            fix is not None
            and fix.apply is not None
            and (fix.safe or self.options.unsafe)
            and self.keep(finding)
        )

    def _shown_layer(self, finding: Finding, fix: Fix) -> str | None:
        layer = self._target_layer(finding, fix)
        return _layer_path(layer) if layer is not None else finding.location.layer

    def _editable(self, finding: Finding, fix: Fix) -> tuple[Sdf.Layer | None, str | None]:
        """The layer the fix edits, and why it may not (None: it may)."""
        assert self.stage is not None and self.sources is not None
        layer = self._target_layer(finding, fix)
        if layer is not None and self.in_memory and not self._in_layer_stack(layer):
            # USD edits only the layer stack: a layer a reference brings in is
            # overridden from the session layer (its composed effect is what counts).
            layer = self.stage.GetSessionLayer()
        if layer is None or not (self.in_memory or self._in_layer_stack(layer)):
            return None, (
                "its layer is outside the stage's layer stack (a reference or payload brings "
                "it in); fix that file itself, or use --fix-to"
            )
        return layer, self.sources.problem(layer)

    def _alone(self, finding: Finding, fix: Fix) -> tuple[str | None, LintRun[None] | None]:
        """Apply one fix and check it. Returns why it was not applied (None: it
        was) and, when it was, the lint of the stage after it."""
        assert self.stage is not None and self.sources is not None
        layer, problem = self._editable(finding, fix)
        if problem is not None or layer is None:
            return problem, None
        checkpoint = self.sources.checkpoint()
        touched: list[Sdf.Layer] = []
        try:
            touched, paths, failure = self._apply(fix, layer)
            failure = failure or self._also_edits(touched, layer) or self.sources.commit(touched)
            if failure is not None:
                self.sources.back_to(checkpoint, touched)
                return failure, None
            after = self.linter.run_stage(self.stage, self.path)
        except BaseException:
            self.sources.back_to(checkpoint, touched)
            raise
        if _remains(finding, fix, after):
            self.sources.back_to(checkpoint, touched)
            return (
                "its finding remains after the fix (composition undoes the edit, e.g. a "
                "stronger opinion or a prim that references the fixed one); undone",
                None,
            )
        self.applied.append(Applied(finding, fix, layer, paths, len(self.outcomes)))
        return None, after

    def _apply(
        self, fix: Fix, layer: Sdf.Layer
    ) -> tuple[list[Sdf.Layer], set[Sdf.Path], str | None]:
        """Run ``fix`` with ``layer`` as the edit target; the layers and stage paths
        it changed, and why it failed (None: it ran)."""
        assert self.stage is not None and self.sources is not None
        used = set(self.stage.GetUsedLayers()) | {self.stage.GetSessionLayer()}
        touched: list[Sdf.Layer] = []
        paths: set[Sdf.Path] = set()

        def record_layers(notice, sender) -> None:
            for changed in notice.GetLayers():
                if changed in used and changed not in touched:
                    touched.append(changed)

        def record_paths(notice, sender) -> None:
            paths.update(notice.GetResyncedPaths())
            paths.update(notice.GetChangedInfoOnlyPaths())

        listeners = (
            Tf.Notice.RegisterGlobally(Sdf.Notice.LayersDidChangeSentPerLayer, record_layers),
            Tf.Notice.Register(Usd.Notice.ObjectsChanged, record_paths, self.stage),
        )
        try:
            failure = _call_fix(fix, self.stage, layer)
        finally:
            for listener in listeners:
                listener.Revoke()
        if failure is None and not touched:
            failure = "the fix changed nothing"
        return touched, paths, failure

    def _also_edits(self, touched: list[Sdf.Layer], layer: Sdf.Layer) -> str | None:
        """Why the other layers a fix touched may not change (None: they may)."""
        assert self.stage is not None and self.sources is not None
        for candidate in touched:
            if candidate == layer:
                continue
            problem: str | None
            if candidate == self.stage.GetSessionLayer() and not self.in_memory:
                problem = "the session layer is never saved"
            elif not (self.in_memory or self._in_layer_stack(candidate)):
                problem = "it is outside the stage's layer stack"
            else:
                problem = self.sources.problem(candidate)
            if problem is not None:
                return f"it also edits {_display(candidate)}: {problem}"
        return None

    def _in_layer_stack(self, layer: Sdf.Layer) -> bool:
        assert self.stage is not None
        return layer in self.stage.GetLayerStack(includeSessionLayers=self.in_memory)

    def _target_layer(self, finding: Finding, fix: Fix) -> Sdf.Layer | None:
        assert self.stage is not None
        if fix.layer is not None:
            return fix.layer
        if finding.location.layer is None:
            return self.stage.GetRootLayer()
        return _find_layer(self.stage.GetUsedLayers(), finding.location.layer)

    # -- writing or showing -----------------------------------------------------------

    def _finish(self) -> None:
        assert self.sources is not None
        for source in self.sources:
            if not source.changed or source.disk is None:
                continue
            shown = display_path(source.disk.path)
            if not self.options.write:
                self._show(source, shown)
                continue
            if self.options.before_writing is not None:
                self.options.before_writing()
            try:
                if source.text is not None:
                    save_text(source.disk, source.text)
                else:
                    save_layer(source.layer, source.disk)
            except ChangedOnDisk as exc:
                self._unapply(source.layer, f"{shown} was not written: {exc}")
                self.result.errors.append(f"{shown}: not written: {exc}")
                continue
            except OSError as exc:
                message = exc.strerror or str(exc)
                self._unapply(source.layer, f"writing {shown} failed: {message}")
                self.result.errors.append(f"{shown}: writing failed: {message}")
                continue
            source.layer.Reload(True)  # the layer now matches the file: no longer dirty

    def _show(self, source, shown: str) -> None:
        fixes = [o for o in self.outcomes if o.applied and o.layer == _layer_path(source.layer)]
        listed = ", ".join(sorted({o.code for o in fixes}))
        if source.text is None:
            self.result.notes.append(
                f"--diff: {shown} is a binary (crate) layer, so it is not in the patch; "
                f"--fix would rewrite it with {len(fixes)} fix(es) ({listed})"
            )
            return
        original = source.original_text or ""
        text = patch(source.disk.path, original, source.text, given=self.path)
        if text:
            self.result.diffs.append(text)
            self.result.edits.append((source.disk.path, original, source.text, self.path))

    def _unapply(self, layer: Sdf.Layer, reason: str) -> None:
        """Mark the applied fixes of ``layer`` as not applied, with ``reason``."""
        shown = _layer_path(layer)
        self.result.outcomes[:] = [
            AppliedFix(o.file, o.code, o.path, o.layer, o.description, reason)
            if o.applied and o.layer == shown
            else o
            for o in self.outcomes
        ]


# -- helpers -----------------------------------------------------------------------------


def _outcome(finding: Finding, fix: Fix, layer: str | None, reason: str | None) -> AppliedFix:
    return AppliedFix(
        finding.location.file, finding.code, finding.location.path, layer, fix.description, reason
    )


def _remains(finding: Finding, fix: Fix, after: LintRun[None]) -> bool:
    """Whether the lint after a fix still reports its finding: the same code on
    the same object with the same message, or the same fix offered again."""
    for other in after.findings:
        if other.code != finding.code or other.location.path != finding.location.path:
            continue
        if other.message == finding.message:
            return True
        offered = after.fix(other)
        if offered is not None and offered.description == fix.description:
            return True
    return False


def _call_fix(fix: Fix, stage: Usd.Stage, layer: Sdf.Layer) -> str | None:
    """Run a fix with ``layer`` as the edit target; the reason when it fails."""
    try:
        with Tf.DiagnosticTrap() as trap:
            with Usd.EditContext(stage, Usd.EditTarget(layer)):
                fix.apply(stage)  # type: ignore[misc]
            errors = trap.GetErrors()
            trap.Clear()
    except Exception as exc:  # noqa: BLE001 - a failing fix is reported, never fatal
        debug.show(exc, "a fix raised")
        return f"the fix failed: {type(exc).__name__}: {str(exc).strip()[:200]}"
    if errors:
        return f"the fix failed: {errors[0].commentary.strip()[:200]}"
    return None


def _scope(finding: Finding) -> Sdf.Path | None:
    """What a finding's fix may edit: its object (None: the stage's metadata)."""
    return Sdf.Path(finding.location.path) if finding.location.path else None


class _Scopes:
    """The objects fixed in one round: a set of paths with their ancestors."""

    def __init__(self) -> None:
        self._paths: set[Sdf.Path | None] = set()
        self._ancestors: set[Sdf.Path] = set()

    def overlaps(self, scope: Sdf.Path | None) -> bool:
        """True when ``scope`` is, contains or is inside an object already fixed."""
        if scope is None:
            return None in self._paths
        return scope in self._ancestors or any(p in self._paths for p in scope.GetPrefixes())

    def add(self, scope: Sdf.Path | None) -> None:
        self._paths.add(scope)
        if scope is not None:
            self._ancestors.update(scope.GetPrefixes())


def _fix_key(finding: Finding, fix: Fix | None) -> tuple:
    return (finding.code, finding.location.path, fix.description if fix else None)


def _find_layer(layers: Iterable[Sdf.Layer], name: str) -> Sdf.Layer | None:
    """The layer a finding names (engine.locate writes realPath or identifier)."""
    for layer in layers:
        if name in (_layer_path(layer), layer_identifier(layer)):
            return layer
    return None


def _layer_path(layer: Sdf.Layer) -> str:
    """How findings name a layer (engine.locate): its file, else its identifier."""
    return layer_real_path(layer) or layer_identifier(layer)


def _display(layer: Sdf.Layer) -> str:
    return display_path(_layer_path(layer))
