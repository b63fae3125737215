"""Applies the rules' fixes: ``--fix``, ``--diff`` and ``--fix-to``.

A fix edits the layer that holds the strongest opinion behind its finding
(``Fix.layer`` when the rule names one; the root layer for stage metadata)
through ``Usd.EditContext``, and only a writable layer of the stage's own layer
stack: never a layer a reference or payload brings in. Safe fixes (conditional
ones are only offered when their condition holds) run by default, unsafe ones
on request. Fixing repeats (lint, fix) until no new fix applies, so a fix that
reveals another finding is handled and a second run changes nothing.

Nothing is lost: a layer is saved atomically in its own format, and a ``.usda``
with comments (Sdf drops them on save) is refused unless the user agrees.
With ``--fix-to`` the sources stay untouched: each fix is applied in memory,
its effect on the composed stage is written as overrides (values, blocks,
explicit target lists, customData leaves) into the separate layer, opened as
the session layer, and the source edit is undone; what an override cannot
express (stage metadata, removed or moved prims) is refused.
"""

from __future__ import annotations

import difflib
import os
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from pxr import Sdf, Tf, Usd

from ..api import Fix
from ..api.resolve import mismatched_specs
from ..atomic import replace_atomically
from ..engine import Linter, open_stage
from ..engine.usda_lines import comment_lines
from ..model import AppliedFix, FileResult, Finding
from ..paths import display_path

#: Rounds of (lint, fix): each round fixes what the previous one revealed.
MAX_ROUNDS = 10
CRATE_MAGIC = b"PXR-USDC"


class FixError(Exception):
    """The fixing cannot start (e.g. the --fix-to layer is unusable): one line."""


@dataclass(frozen=True)
class FixOptions:
    #: Apply unsafe fixes too (--unsafe-fixes).
    unsafe: bool = False
    #: Save a .usda although its comments are lost (--fix-drop-comments).
    drop_comments: bool = False
    #: False for --diff: compute the edits, print them, write nothing.
    write: bool = True
    #: Write every fix as an override into this layer (--fix-to).
    fix_to: str | None = None


@dataclass
class FixRun:
    """What fixing a set of files did."""

    outcomes: list[AppliedFix] = field(default_factory=list)
    #: One unified diff per changed layer (--diff).
    diffs: list[str] = field(default_factory=list)
    #: With --fix-to: the findings left on each stage with the overrides applied.
    remaining: list[FileResult] = field(default_factory=list)

    @property
    def applied(self) -> tuple[AppliedFix, ...]:
        return tuple(o for o in self.outcomes if o.applied)

    @property
    def unapplied(self) -> tuple[AppliedFix, ...]:
        return tuple(o for o in self.outcomes if not o.applied)


def fix_files(
    linter: Linter,
    files: Sequence[str],
    options: FixOptions,
    keep: Callable[[Finding], bool] | None = None,
) -> FixRun:
    """Fix each file's stage in turn. ``keep`` says whether a finding is
    reported at all (per-path ignores): a silenced finding is not fixed."""
    run = FixRun()
    override = _open_override_layer(options) if options.fix_to else None
    for path in files:
        if override is not None:
            _reset_to_disk(override, options.fix_to)
        fixer = _StageFixer(linter, path, options, keep or (lambda finding: True), override)
        fixer.run()
        run.outcomes.extend(fixer.outcomes)
        run.diffs.extend(fixer.diffs)
        if fixer.remaining is not None:
            run.remaining.append(fixer.remaining)
    return run


# -- one stage -------------------------------------------------------------------


class _StageFixer:
    def __init__(
        self,
        linter: Linter,
        path: str,
        options: FixOptions,
        keep: Callable[[Finding], bool],
        override: Sdf.Layer | None,
    ) -> None:
        self.linter = linter
        self.path = path
        self.options = options
        self.keep = keep
        self.override = override
        self.outcomes: list[AppliedFix] = []
        self.diffs: list[str] = []
        self.remaining: FileResult | None = None
        self.stage: Usd.Stage | None = None
        #: Why a layer may not be edited, by identifier (None: it may).
        self._layer_problem: dict[str, str | None] = {}
        #: The fixes applied in place so far, in order, with their layers.
        self._applied: list[tuple[Fix, Sdf.Layer]] = []
        #: --fix-to: source layers as on disk, by identifier; the override layer
        #: as it started; the composed states written for each applied fix.
        self._pristine: dict[str, Sdf.Layer] = {}
        self._override_start = _snapshot(override) if override is not None else None
        self._overrides: list[dict[Sdf.Path, _State]] = []

    def run(self) -> None:
        opened = open_stage(self.path, self.override)
        if opened.stage is None:
            # Nothing to fix; the report says why (ST001, a missing file, ...).
            if self.override is not None:
                self.remaining = self.linter.lint_path(self.path)
            return
        self.stage = opened.stage
        # USD's own warnings (e.g. while exporting a spline) stay off the user's stderr.
        with Tf.DiagnosticTrap() as trap:
            try:
                findings = self._rounds()
                if self.override is not None:
                    self._finish_override(findings)
                else:
                    self._finish_in_place()
            finally:
                self._discard_unsaved()
                self.stage = None
                trap.Clear()

    def _rounds(self) -> list[Finding]:
        tried: set[tuple] = set()
        for _ in range(MAX_ROUNDS + 1):
            pairs = self.linter.lint_stage_with_fixes(self.stage, self.path)
            todo = [
                (finding, fix)
                for finding, fix in pairs
                if fix is not None
                and fix.apply is not None
                and (fix.safe or self.options.unsafe)
                and _fix_key(finding, fix) not in tried
                and self.keep(finding)
            ]
            if not todo:
                return [finding for finding, _ in pairs]
            edited = _Scopes()
            for finding, fix in todo:
                scope = _scope(finding)
                # Two fixes on one object (or a prim and its property) in one round
                # could undo each other: the second waits for the next round's findings.
                if edited.overlaps(scope):
                    continue
                tried.add(_fix_key(finding, fix))
                edited.add(scope)
                try:
                    outcome = self._fix_one(finding, fix)
                except Exception as exc:  # noqa: BLE001 - one fix must not cost the others
                    self._recover()
                    reason = f"internal error while fixing: {type(exc).__name__}: {exc}"
                    outcome = self._outcome(finding, fix, finding.location.layer, reason)
                self.outcomes.append(outcome)
        return [finding for finding, _ in self.linter.lint_stage_with_fixes(self.stage, self.path)]

    def _outcome(
        self, finding: Finding, fix: Fix, layer: str | None, reason: str | None = None
    ) -> AppliedFix:
        return AppliedFix(
            finding.location.file,
            finding.code,
            finding.location.path,
            layer,
            fix.description,
            reason,
        )

    def _fix_one(self, finding: Finding, fix: Fix) -> AppliedFix:
        layer = self._target_layer(finding, fix)
        if layer is None and self.override is not None:
            # A referenced layer is not edited even in memory: the fix authors its
            # values straight into the override layer, at the stage's paths.
            layer = self.override
        if layer is None:
            return self._outcome(
                finding,
                fix,
                finding.location.layer,
                "its layer is outside the stage's layer stack (a reference or payload brings "
                "it in); fix that file itself, or use --fix-to",
            )
        shown = _layer_path(layer)
        if self.override is not None:
            reason = self._apply_as_override(fix, layer)
            return self._outcome(finding, fix, _layer_path(self.override), reason)
        problem = self._problem(layer)
        if problem is not None:
            return self._outcome(finding, fix, shown, problem)
        return self._outcome(finding, fix, shown, self._apply_in_place(fix, layer))

    def _target_layer(self, finding: Finding, fix: Fix) -> Sdf.Layer | None:
        stage = self.stage
        if fix.layer is not None:
            layer = fix.layer
        elif finding.location.layer is None:
            layer = stage.GetRootLayer()
        else:
            layer = _find_layer(stage.GetUsedLayers(), finding.location.layer)
        if layer is None:
            return None
        if self.override is not None and layer == self.override:
            return layer
        own = stage.GetLayerStack(includeSessionLayers=False)
        return layer if layer in own else None

    def _problem(self, layer: Sdf.Layer) -> str | None:
        if layer.identifier not in self._layer_problem:
            self._layer_problem[layer.identifier] = write_problem(layer, self.options.drop_comments)
        return self._layer_problem[layer.identifier]

    # -- editing --------------------------------------------------------------

    def _apply_in_place(self, fix: Fix, layer: Sdf.Layer) -> str | None:
        """Apply ``fix`` with ``layer`` as the edit target; undo it all on failure."""
        stack = self.stage.GetLayerStack(includeSessionLayers=True)
        used = self.stage.GetUsedLayers()
        touched: list[Sdf.Layer] = []

        def record(notice, sender) -> None:
            for changed in notice.GetLayers():
                if changed in used and changed not in touched:
                    touched.append(changed)

        listener = Tf.Notice.RegisterGlobally(Sdf.Notice.LayersDidChangeSentPerLayer, record)
        try:
            failure = _call_fix(fix, self.stage, layer)
        finally:
            listener.Revoke()
        if failure is None and not touched:
            failure = "the fix changed nothing"
        for candidate in touched:
            if failure is not None or candidate == layer:
                continue
            if candidate == self.stage.GetSessionLayer():
                problem = "the session layer is never saved"
            elif candidate not in stack:
                problem = "it is outside the stage's layer stack"
            else:
                problem = self._problem(candidate)
            if problem is not None:
                failure = f"it also edits {_display(candidate)}: {problem}"
        if failure is None:
            self._applied.append((fix, layer))
        elif touched:
            self._undo()
        return failure

    def _recover(self) -> None:
        """Back to the state of the fixes applied so far, after an unexpected error."""
        if self.override is None:
            self._undo()
            return
        for layer in self.stage.GetLayerStack(includeSessionLayers=False):
            if layer.dirty and not layer.anonymous:
                layer.Reload(True)
        self._rebuild_override()

    def _undo(self) -> None:
        """Undo a failed fix: reload the edited layers from disk and apply again
        the fixes that succeeded, in order (cheaper than a copy before every fix)."""
        self.stage.GetSessionLayer().Clear()
        for candidate in self.stage.GetUsedLayers():
            if candidate.dirty and not candidate.anonymous:
                candidate.Reload(True)
        for fix, layer in self._applied:
            _call_fix(fix, self.stage, layer)

    def _apply_as_override(self, fix: Fix, layer: Sdf.Layer) -> str | None:
        """Apply ``fix`` in ``layer`` in memory, undo it, then write what it changed
        on the composed stage into the override layer (the sources stay as on disk)."""
        stage = self.stage
        changed: set[Sdf.Path] = set()
        touched: set[Sdf.Layer] = set()

        def record_paths(notice, sender) -> None:
            changed.update(notice.GetResyncedPaths())
            changed.update(notice.GetChangedInfoOnlyPaths())

        def record_layers(notice, sender) -> None:
            touched.update(notice.GetLayers())

        if layer != self.override:
            self._keep_pristine(layer)
        listeners = (
            Tf.Notice.Register(Usd.Notice.ObjectsChanged, record_paths, stage),
            Tf.Notice.RegisterGlobally(Sdf.Notice.LayersDidChangeSentPerLayer, record_layers),
        )
        try:
            failure = _call_fix(fix, stage, layer)
        finally:
            for listener in listeners:
                listener.Revoke()
        if failure is None and Sdf.Path.absoluteRootPath in changed:
            failure = (
                "it edits stage metadata, which USD reads only from a stage's root or "
                "session layer, so an override layer used as a sublayer cannot carry it; use --fix"
            )
        after = _capture(stage, changed) if failure is None else {}
        # Undo: the sources are never saved with --fix-to, and the override
        # layer gets the composed difference below, whichever layer the fix edited.
        self._undo_edits(touched, changed)
        if failure is not None:
            return failure
        before = _capture(stage, changed)
        paths = set(after) | set(before)
        wanted = {path: after.get(path, _absent(path)) for path in paths}
        todo = {p: wanted[p] for p in paths if wanted[p] != before.get(p, _absent(p))}
        if not todo:
            return "the fix changed nothing on the stage"
        _author_all(stage, self.override, todo)
        now = _capture(stage, changed)
        wrong = sorted(p for p in paths if now.get(p, _absent(p)) != wanted[p])
        if wrong:
            self._rebuild_override()
            if wanted[wrong[0]] == _absent(wrong[0]) and not wrong[0].IsPropertyPath():
                return f"it removes or moves <{wrong[0]}>, which an override cannot do; use --fix"
            return f"its effect on <{wrong[0]}> cannot be written as an override; use --fix"
        self._overrides.append(todo)
        return None

    def _keep_pristine(self, layer: Sdf.Layer) -> None:
        """A copy of a source layer as on disk, to undo edits path by path."""
        if layer.identifier not in self._pristine:
            self._pristine[layer.identifier] = _snapshot(layer)

    def _undo_edits(self, touched: set[Sdf.Layer], changed: set[Sdf.Path]) -> None:
        """Put every layer a fix edited back as it was (no full reload per fix)."""
        # Sources first: the override's earlier states are authored against them.
        for layer in sorted(touched, key=lambda layer: layer == self.override):
            pristine = self._pristine.get(layer.identifier)
            if layer == self.override:
                self._rebuild_override()
            elif pristine is not None and Sdf.Path.absoluteRootPath not in changed:
                _restore_specs(layer, pristine, changed)
            elif layer.dirty and not layer.anonymous:
                layer.Reload(True)

    def _rebuild_override(self) -> None:
        """The override layer as it started plus the overrides of the fixes applied."""
        self.override.TransferContent(self._override_start)
        for todo in self._overrides:
            _author_all(self.stage, self.override, todo)

    # -- saving -----------------------------------------------------------------

    def _finish_in_place(self) -> None:
        for layer in self.stage.GetLayerStack(includeSessionLayers=False):
            if not layer.dirty:
                continue
            target = layer.realPath
            if not self.options.write:
                self.diffs.append(_diff(target, _disk_text(target), layer.ExportToString()))
                continue
            try:
                save_layer(layer, target)
            except OSError as exc:
                self._unapply(layer, f"writing {_display(layer)} failed: {exc}")

    def _finish_override(self, findings: list[Finding]) -> None:
        self.remaining = FileResult(self.path, findings=tuple(findings))
        if not any(outcome.applied for outcome in self.outcomes):
            return  # refused fixes may leave the layer dirty, never changed
        try:
            save_layer(self.override, self.options.fix_to)
        except OSError as exc:
            self._unapply(self.override, f"writing {self.options.fix_to} failed: {exc}")

    def _unapply(self, layer: Sdf.Layer, reason: str) -> None:
        """Mark the applied fixes of ``layer`` as not applied, with ``reason``."""
        shown = _layer_path(layer)
        self.outcomes = [
            AppliedFix(o.file, o.code, o.path, o.layer, o.description, reason)
            if o.applied and o.layer == shown
            else o
            for o in self.outcomes
        ]

    def _discard_unsaved(self) -> None:
        """Forget in-memory edits (--diff, failed writes): a later open of the same
        layer in this process must read the file, not the registry's edited copy."""
        if self.stage is None:
            return
        for layer in self.stage.GetUsedLayers():
            if layer.dirty and not layer.anonymous and os.path.exists(layer.realPath):
                layer.Reload(True)


# -- layers and files ---------------------------------------------------------------


def write_problem(layer: Sdf.Layer, drop_comments: bool = False) -> str | None:
    """Why --fix may not save ``layer``, or None when it may."""
    path = layer.realPath
    if layer.anonymous or not path:
        return f"{layer.GetDisplayName()} is not a file on disk"
    if layer.GetFileFormat().IsPackage() or layer.identifier.endswith("]"):
        return f"{_display(layer)} is inside a .usdz package, which --fix does not rewrite"
    # A file without write permission is read-only even to root, who may write it anyway.
    if not os.access(path, os.W_OK) or not os.stat(path).st_mode & 0o222:
        return f"{_display(layer)} is read-only"
    folder = os.path.dirname(path) or "."
    if not os.access(folder, os.W_OK | os.X_OK):
        return f"the folder of {_display(layer)} is read-only (the safe write needs it)"
    if not drop_comments and not _is_crate(path):
        lines = comment_lines(_disk_text(path))
        if lines:
            return (
                f"{_display(layer)} has comments (line {lines[0]}) that saving would drop; "
                "use --fix-to LAYER to write the fixes to a separate layer, or "
                "--fix-drop-comments to accept losing them"
            )
    return None


def save_layer(layer: Sdf.Layer, target: str) -> None:
    """Write ``layer`` to ``target`` atomically, in the target's own format: a
    temporary file with the same extension in the same folder, then
    ``os.replace``. Raises OSError; the old file is intact on any failure."""
    # Through a symbolic link, replace the file it points to, not the link.
    destination = Path(os.path.realpath(target))
    args = {}
    if destination.suffix.lower() == ".usd" and destination.exists():
        # A .usd keeps the encoding it has (a new one gets USD's default).
        args["format"] = "usdc" if _is_crate(str(destination)) else "usda"
    replace_atomically(
        destination, lambda temporary: _export(layer, str(temporary), args), destination.suffix
    )
    layer.Reload(True)  # the layer now matches the file: no longer dirty


def _export(layer: Sdf.Layer, path: str, args: dict[str, str]) -> None:
    """Sdf's export, with its errors as OSError (a test replaces this to fail)."""
    try:
        with Tf.DiagnosticTrap() as trap:
            ok = layer.Export(path, args=args)
            trap.Clear()
    except Tf.ErrorException as exc:
        raise OSError(str(exc).strip().splitlines()[-1]) from None
    if not ok:
        raise OSError(f"USD could not write {path}")


def _open_override_layer(options: FixOptions) -> Sdf.Layer:
    """The --fix-to layer: opened when it exists, else created in memory."""
    path = options.fix_to
    target = Path(path)
    if target.is_dir():
        raise FixError(f"--fix-to {path}: is a directory")
    file_format = Sdf.FileFormat.FindByExtension(target.suffix.lstrip("."))
    if file_format is None or file_format.IsPackage():
        raise FixError(f"--fix-to {path}: the layer must be a .usda, .usdc or .usd file")
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise FixError(f"--fix-to {path}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK) or (
        target.exists() and not os.access(target, os.W_OK)
    ):
        raise FixError(f"--fix-to {path}: not writable")
    if not target.exists():
        return Sdf.Layer.New(file_format, str(target.resolve()))
    with Tf.DiagnosticTrap() as trap:
        try:
            layer = Sdf.Layer.FindOrOpen(str(target))
        except Tf.ErrorException:
            layer = None
        trap.Clear()
    if layer is None:
        raise FixError(f"--fix-to {path}: USD cannot read this layer")
    lines = [] if options.drop_comments or _is_crate(path) else comment_lines(_disk_text(path))
    if lines:
        raise FixError(
            f"--fix-to {path}: the layer has comments (line {lines[0]}) that saving would drop; "
            "use another layer, or --fix-drop-comments to accept losing them"
        )
    return layer


def _reset_to_disk(layer: Sdf.Layer, path: str) -> None:
    """Start each stage from the override layer as saved."""
    if os.path.exists(path) and layer.dirty:
        layer.Reload(True)


def _find_layer(layers: Iterable[Sdf.Layer], name: str) -> Sdf.Layer | None:
    """The layer a finding names (engine.locate writes realPath or identifier)."""
    for layer in layers:
        if name in (_layer_path(layer), layer.identifier):
            return layer
    return None


def _is_crate(path: str) -> bool:
    try:
        with open(path, "rb") as handle:
            return handle.read(len(CRATE_MAGIC)) == CRATE_MAGIC
    except OSError:
        return False


def _disk_text(path: str) -> str:
    """A layer file as text: a .usda as written, a crate file as Sdf exports it."""
    if _is_crate(path):
        return Sdf.Layer.OpenAsAnonymous(path).ExportToString()
    with open(path, encoding="utf-8", errors="replace") as handle:
        return handle.read()


def _diff(path: str, old: str, new: str) -> str:
    name = display_path(path)
    return "".join(
        difflib.unified_diff(
            old.splitlines(keepends=True),
            new.splitlines(keepends=True),
            fromfile=f"a/{name}",
            tofile=f"b/{name}",
        )
    )


def _layer_path(layer: Sdf.Layer) -> str:
    """How findings name a layer (engine.locate): its file, else its identifier."""
    return layer.realPath or layer.identifier


def _display(layer: Sdf.Layer) -> str:
    return display_path(_layer_path(layer))


def _snapshot(layer: Sdf.Layer) -> Sdf.Layer:
    copy = Sdf.Layer.CreateAnonymous(".usda")
    copy.TransferContent(layer)
    return copy


def _call_fix(fix: Fix, stage: Usd.Stage, layer: Sdf.Layer) -> str | None:
    """Run a fix with ``layer`` as the edit target; the reason when it fails."""
    try:
        with Tf.DiagnosticTrap() as trap:
            with Usd.EditContext(stage, Usd.EditTarget(layer)):
                fix.apply(stage)
            errors = trap.GetErrors()
            trap.Clear()
    except Exception as exc:  # noqa: BLE001 - a failing fix is reported, never fatal
        return f"the fix failed: {type(exc).__name__}: {str(exc).strip()[:200]}"
    if errors:
        return f"the fix failed: {errors[0].commentary.strip()[:200]}"
    return None


def _fix_key(finding: Finding, fix: Fix) -> tuple:
    return (finding.code, finding.location.path, fix.description)


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


# -- composed state, for --fix-to ---------------------------------------------------

#: A prim or property as a consumer sees it, comparable by value; the last item
#: is what _author needs to write it (kept out of comparisons by _State.__eq__).
_NO_VALUE = ("value", None)


@dataclass(frozen=True)
class _State:
    key: tuple
    payload: object = field(default=None, compare=False)


def _absent(path: Sdf.Path) -> _State:
    return _State(_NO_VALUE if path.IsPropertyPath() else ("absent",))


def _capture(stage: Usd.Stage, changed: Iterable[Sdf.Path]) -> dict[Sdf.Path, _State]:
    """The composed state of every changed object; a changed prim brings its
    whole subtree (a resync can change anything below it)."""
    states: dict[Sdf.Path, _State] = {}
    for path in changed:
        if path == Sdf.Path.absoluteRootPath:
            continue
        if path.IsPropertyPath():
            prop_path = path.GetParentPath() if path.IsTargetPath() else path
            states[prop_path] = _property_state(stage.GetPropertyAtPath(prop_path))
            continue
        prim = stage.GetPrimAtPath(path)
        if not prim:
            continue
        for descendant in Usd.PrimRange(prim, Usd.PrimAllPrimsPredicate):
            states[descendant.GetPath()] = _prim_state(descendant)
            for prop in descendant.GetProperties():
                states[prop.GetPath()] = _property_state(prop)
    return states


def _prim_state(prim: Usd.Prim) -> _State:
    """Type, specifier, activation and customData (as leaf key paths: dictionaries
    compose key by key, so a stronger layer sets a leaf, never removes it)."""
    leaves = dict(_leaves(prim.GetCustomData()))
    key = (
        "prim",
        prim.GetTypeName(),
        prim.IsDefined(),
        prim.IsActive(),
        tuple(sorted((name, repr(value)) for name, value in leaves.items())),
    )
    return _State(key, leaves)


def _leaves(dictionary: dict, prefix: str = ""):
    for name, value in dictionary.items():
        if isinstance(value, dict) and value:
            yield from _leaves(value, f"{prefix}{name}:")
        else:
            yield f"{prefix}{name}", value


def _property_state(prop: Usd.Property | None) -> _State:
    if isinstance(prop, Usd.Relationship) and prop:
        targets = tuple(prop.GetTargets())
        return _State(("rel", tuple(map(str, targets))), targets) if targets else _State(_NO_VALUE)
    if isinstance(prop, Usd.Attribute) and prop and prop.HasAuthoredValue():
        default = prop.Get(Usd.TimeCode.Default())
        samples = tuple((time, prop.Get(time)) for time in prop.GetTimeSamples())
        # A weaker mistyped spec stays an SE016 finding although a stronger one hides it.
        mistyped = bool(mismatched_specs(prop))
        key = ("attr", str(prop.GetTypeName()), repr(default), repr(samples), mistyped)
        return _State(key, (prop.GetTypeName(), prop.IsCustom(), default, samples))
    return _State(_NO_VALUE)


def _restore_specs(layer: Sdf.Layer, pristine: Sdf.Layer, paths: Iterable[Sdf.Path]) -> None:
    """Make the specs at ``paths`` (and below) of ``layer`` as in ``pristine``."""
    for path in sorted(paths, key=lambda p: p.pathElementCount):
        if path.IsTargetPath():
            path = path.GetParentPath()
        if pristine.GetObjectAtPath(path):
            parent = path.GetParentPath()
            if not parent.IsAbsoluteRootPath() and not layer.GetPrimAtPath(parent.GetPrimPath()):
                Sdf.CreatePrimInLayer(layer, parent.GetPrimPath())
            Sdf.CopySpec(pristine, path, layer, path)
            continue
        spec = layer.GetObjectAtPath(path)
        if spec is None:
            continue
        if path.IsPropertyPath():
            spec.owner.RemoveProperty(spec)
        elif spec.nameParent:
            del spec.nameParent.nameChildren[spec.name]
        else:
            del layer.rootPrims[spec.name]


def _author_all(stage: Usd.Stage, layer: Sdf.Layer, states: dict[Sdf.Path, _State]) -> None:
    """Author ``states`` into ``layer``: prims before their properties, parents first."""
    with Usd.EditContext(stage, Usd.EditTarget(layer)):
        for path in sorted(states, key=lambda p: (p.IsPropertyPath(), p.pathElementCount, p)):
            _author(stage, path, states[path])


def _author(stage: Usd.Stage, path: Sdf.Path, state: _State) -> None:
    """Make the composed ``path`` match ``state`` by authoring in the edit target."""
    kind = state.key[0]
    if not path.IsPropertyPath():
        if kind == "prim":
            _, type_name, defined, active, _ = state.key
            prim = stage.GetPrimAtPath(path)
            if not prim or not prim.IsDefined() and defined:
                prim = stage.DefinePrim(path, type_name)
            if prim.GetTypeName() != type_name:
                prim.SetTypeName(type_name)
            if prim.IsActive() != active:
                prim.SetActive(active)
            current = dict(_leaves(prim.GetCustomData()))
            for name, value in state.payload.items():
                if name not in current or repr(current[name]) != repr(value):
                    prim.SetCustomDataByKey(name, value)
        return  # a prim that must disappear cannot: the caller's check reports it
    prim = stage.GetPrimAtPath(path.GetPrimPath())
    if not prim:
        return  # its prim cannot be brought back: the caller's check reports it
    current = prim.GetProperty(path.name)
    if kind == "rel":
        rel = prim.GetRelationship(path.name) or prim.CreateRelationship(path.name)
        rel.SetTargets(list(state.payload))
    elif kind == "attr":
        type_name, custom, default, samples = state.payload
        attr = prim.GetAttribute(path.name) or prim.CreateAttribute(path.name, type_name, custom)
        attr.Clear()
        if default is not None:
            attr.Set(default)
        for time, value in samples:
            attr.Set(value, time)
    elif isinstance(current, Usd.Attribute) and current:
        attr = prim.GetAttribute(path.name)
        attr.Block()  # the fix removed every value: block the weaker ones
    elif isinstance(current, Usd.Relationship) and current:
        current.SetTargets([])  # an explicit empty list hides the weaker targets
