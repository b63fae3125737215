"""``--fix-to LAYER``: the fixes as overrides in a layer of their own.

The sources stay untouched. The stage is fixed in memory exactly as ``--fix``
fixes it (the same fixes, each verified, :class:`.session.StageFixer`); then
the in-memory edits are dropped and LAYER is made to give the same composed
result on top of the sources:

- LAYER becomes the stage's new root: it sublayers the stage's root layer and
  carries the root layer's stage metadata (``renderSettingsPrimPath``, time
  codes, ``upAxis``...; USD reads those from the root layer only), so stage
  metadata fixes apply too;
- every object a fix changed is written as its composed state: a value as that
  value, a removed value as the schema fallback (so ``Get()`` returns what it
  returns after ``--fix``; a block where a rule wants no authored opinion at all,
  e.g. SE007), removed targets as an explicit list, a removed prim deactivated,
  a moved prim defined at its new path with its composed opinions;
- each fix is checked on the stage LAYER roots: its objects compose as after
  ``--fix`` and its finding is gone, else it is reported as not applied.

An existing LAYER is added to (and, as text, edited like any source: its
comments stay); a fix already in it is not reported again.
"""

from __future__ import annotations

import contextlib
import os
from collections import Counter
from collections.abc import Callable, Iterable, Sequence
from dataclasses import field
from pathlib import Path
from typing import Any

from pxr import Sdf, Tf, Usd

from ..api.resolve import mismatched_specs
from ..engine import Linter, open_stage
from ..layers.files import layer_identifier, layer_real_path
from ..layers.writing import ChangedOnDisk, DiskState, save_layer, save_new_layer, save_text
from ..model import AppliedFix, FileResult, Finding
from ..paths import display_path, escape, usd_path
from ..records import record
from .session import Applied, FixError, FixOptions, FixRun, StageFixer
from .text_edits import CannotEdit, edit_text

#: Root layer fields that are not stage metadata.
_NOT_STAGE_METADATA = frozenset(
    {"subLayers", "subLayerOffsets", "primChildren", "documentation", "comment"}
)


def fix_to(
    linter: Linter, files: Sequence[str], options: FixOptions, keep: Callable[[Finding], bool]
) -> FixRun:
    assert options.fix_to is not None
    run = FixRun()
    if len(files) != 1:
        raise FixError(f"--fix-to writes the overrides of one stage; got {len(files)} files")
    path = files[0]
    source = open_stage(path).stage
    if source is None:  # the report says why (ST001, a missing file, ...)
        run.remaining.append(linter.lint_path(path))
        return run
    overlay = _OverlayLayer.open(options.fix_to)
    if overlay.layer in source.GetUsedLayers() or _a_used_file(overlay.path, source):
        raise FixError(f"--fix-to {overlay.path}: the layer is part of the stage it fixes")
    root = source.GetRootLayer()
    overlay.root_path = layer_real_path(root)
    if overlay.root_path != escape(overlay.root_path):
        # The overlay sublayers the root, and an asset path must be UTF-8 (Sdf refuses it).
        raise FixError(
            f"--fix-to {overlay.path}: the stage's file name {display_path(path)} is not "
            "valid UTF-8, and a layer can only name a file whose name is"
        )
    overlay.root_metadata = _stage_metadata(root)
    overlay.reset()
    # The fixes run on the stage the overlay roots, in memory, as --fix runs them.
    stage = Usd.Stage.Open(overlay.layer)
    session = StageFixer(linter, path, options, keep, in_memory=True)
    try:
        session.run(stage)
        builder = _Builder(linter, path, session, overlay, stage)
    finally:
        session.close()
    builder.build()
    run.outcomes.extend(builder.outcomes)
    run.errors.extend(builder.errors)
    run.remaining.append(FileResult(path, findings=tuple(builder.findings)))
    return run


def _a_used_file(path: str, stage: Usd.Stage) -> bool:
    """Whether ``path`` is the file of a layer ``stage`` uses under another name
    (a symbolic or hard link to it): Sdf tells layers apart by name, and writing
    the overrides there would edit that source."""
    if not os.path.exists(path):
        return False
    for layer in stage.GetUsedLayers():
        with contextlib.suppress(OSError):  # not a file (anonymous, a package member)
            if os.path.samefile(path, layer_real_path(layer)):
                return True
    return False


# -- the override layer ------------------------------------------------------------------


@record
class _OverlayLayer:
    path: str
    layer: Sdf.Layer
    #: The file as read (None: a new layer).
    disk: DiskState | None
    #: The layer as it started, and Sdf's export of it.
    start: Sdf.Layer
    exported: str
    #: The stage's root layer, which the overlay sublayers, and its stage metadata.
    root_path: str = ""
    root_metadata: dict[str, object] = field(default_factory=dict)

    def reset(self) -> None:
        """The layer as it started, rooting the stage: it sublayers the stage's root
        layer and has its stage metadata (USD reads those from the root only)."""
        self.layer.TransferContent(self.start)
        _add_sublayer(self.layer, self.root_path)
        _set_metadata(self.layer, self.root_metadata)

    @classmethod
    def open(cls, path: str) -> _OverlayLayer:
        """The --fix-to layer: opened when it exists, else created in memory."""
        target = Path(path)
        file_format = _writable_layer_format(path, target)
        if not target.exists():
            layer = Sdf.Layer.New(file_format, usd_path(str(target.resolve())))
            return cls(path, layer, None, _snapshot(layer), layer.ExportToString())
        with Tf.DiagnosticTrap() as trap:
            try:
                layer = Sdf.Layer.FindOrOpen(usd_path(str(target)))
            except Tf.ErrorException:
                layer = None
            trap.Clear()
        if layer is None:
            raise FixError(f"--fix-to {path}: USD cannot read this layer")
        if layer.dirty:
            layer.Reload(True)
        try:
            disk = DiskState.read(str(target))
        except OSError as exc:
            raise FixError(f"--fix-to {path}: {exc.strerror or exc}") from None
        return cls(path, layer, disk, _snapshot(layer), layer.ExportToString())

    def save(self) -> None:
        """Write the layer (raises OSError): an existing text layer by a text edit."""
        if self.disk is None:
            save_new_layer(self.layer, self.path)
        elif self.disk.is_crate:
            save_layer(self.layer, self.disk)
        else:
            original = self.disk.data.decode("utf-8")
            try:
                text = edit_text(original, self.exported, self.layer.ExportToString())
            except CannotEdit as exc:
                raise OSError(f"the overrides cannot be written as a text edit: {exc}") from None
            save_text(self.disk, text)


def _writable_layer_format(path: str, target: Path) -> Sdf.FileFormat:
    """The file format of the --fix-to layer ``path``; FixError when it cannot be one."""
    if target.is_dir():
        raise FixError(f"--fix-to {path}: is a directory")
    if target.exists() and not target.is_file():  # /dev/null, a FIFO: no layer to keep
        raise FixError(f"--fix-to {path}: not a regular file; name a .usda, .usdc or .usd file")
    suffix = target.suffix.lstrip(".")
    # Sdf raises for an empty extension (a name without one).
    file_format = Sdf.FileFormat.FindByExtension(suffix) if suffix else None
    if file_format is None or file_format.IsPackage():
        raise FixError(f"--fix-to {path}: the layer must be a .usda, .usdc or .usd file")
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise FixError(f"--fix-to {path}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK) or (
        target.exists() and not os.access(target, os.W_OK)
    ):
        raise FixError(f"--fix-to {path}: not writable")
    links = target.stat().st_nlink if target.exists() else 1
    if links > 1:  # as --fix leaves such a source alone (writing.write_problem)
        raise FixError(
            f"--fix-to {path}: has {links} hard links, which replacing it would split; "
            "name another layer"
        )
    return file_format


# -- building the overrides ----------------------------------------------------------------


class _Builder:
    """Turns the fixed in-memory stage into overrides on the overlay's stage."""

    def __init__(
        self,
        linter: Linter,
        path: str,
        session: StageFixer,
        overlay: _OverlayLayer,
        stage: Usd.Stage,
    ) -> None:
        self.linter = linter
        self.path = path
        self.overlay = overlay
        self.stage = stage
        self.before_writing = session.options.before_writing
        self.outcomes: list[AppliedFix] = list(session.outcomes)
        self.errors: list[str] = []
        self.findings: list[Finding] = list(session.findings)
        self.applied: list[Applied] = list(session.applied)
        everything = set().union(*(a.paths for a in self.applied)) if self.applied else set()
        self.fixed = _capture(stage, everything)
        #: Prims in the fixed stage's order: the overlay authors them in it.
        self.order = {
            prim.GetPath(): index
            for index, prim in enumerate(Usd.PrimRange.Stage(stage, Usd.PrimAllPrimsPredicate))
        }
        self.root_children = _child_names(stage.GetPseudoRoot())
        self.owned = [set(_capture(stage, a.paths)) for a in self.applied]
        self.meta_owners = [Sdf.Path.absoluteRootPath in a.paths for a in self.applied]
        self.fixed_meta = _stage_metadata(overlay.layer)
        self.fixed_findings = Counter(_finding_key(f) for f in session.findings)
        #: Attributes a fix left without an authored value that are written as a block.
        self.blocked: set[Sdf.Path] = set()
        self.dropped: dict[int, str] = {}

    def build(self) -> None:
        if not self.applied:
            return
        stage = self.stage
        self.overlay.reset()
        with Tf.DiagnosticTrap() as trap:
            try:
                for owned, applied in zip(self.owned, self.applied, strict=True):
                    owned |= set(_capture(stage, applied.paths))  # what it removed, too
                self.before = _capture(stage, self.fixed)
                self._settle()
                self._save()
            finally:
                trap.Clear()

    def _todo(self) -> dict[Sdf.Path, _State]:
        kept = [i for i in range(len(self.applied)) if i not in self.dropped]
        wanted = set().union(*(self.owned[i] for i in kept)) if kept else set()
        paths = set(self.fixed) | set(self.before)
        todo = {}
        for path in paths:
            if path not in wanted or self._under_absent(path):
                continue
            state = self.fixed.get(path, _absent(path))
            if state != self.before.get(path, _absent(path)):
                todo[path] = state
        return todo

    def _under_absent(self, path: Sdf.Path) -> bool:
        """Whether an ancestor prim is gone after the fixes (deactivating it is enough)."""
        return any(self.fixed.get(prefix) == _ABSENT for prefix in path.GetPrefixes()[:-1])

    def _author(self) -> dict[Sdf.Path, _State]:
        """The overlay as it started, plus the overrides of the fixes kept."""
        overlay = self.overlay
        overlay.reset()
        todo = self._todo()
        _author_all(self.stage, overlay.layer, todo, self.blocked, self.order)
        if _child_names(self.stage.GetPseudoRoot()) != self.root_children:
            overlay.layer.rootPrimOrder = list(self.root_children)
        if any(self.meta_owners[i] for i in range(len(self.applied)) if i not in self.dropped):
            _set_metadata(overlay.layer, self.fixed_meta)
        return todo

    def _settle(self) -> None:
        """Author, check, drop what does not hold, until everything left holds."""
        for _ in range(len(self.applied) + 2):
            todo = self._author()
            now = _capture(self.stage, self.fixed)
            wrong = {
                path
                for path, state in todo.items()
                if not _matches(now.get(path, _absent(path)), state)
            }
            failing = {i for i, owned in enumerate(self.owned) if owned & wrong}
            findings = self.linter.run_stage(self.stage, self.path).findings
            remaining = self._still_found(findings)
            blockable = self._blockable(todo, remaining)
            if blockable and not failing - self.dropped.keys():
                self.blocked |= blockable
                continue
            new = (failing | remaining) - self.dropped.keys()
            if not new:
                self.findings = list(findings)
                self._report(todo)
                return
            for i in new:
                self.dropped[i] = self._reason(i, wrong)
        raise FixError("--fix-to: the overrides did not settle")  # pragma: no cover

    def _still_found(self, findings: Sequence[Finding]) -> set[int]:
        """The kept fixes whose finding the overlay leaves and --fix does not: on a
        fix's object, its fault."""
        extra = Counter(_finding_key(f) for f in findings) - self.fixed_findings
        return {
            i
            for i, a in enumerate(self.applied)
            if i not in self.dropped
            and any(key[:2] == _finding_key(a.finding)[:2] for key in extra)
        }

    def _blockable(self, todo: dict[Sdf.Path, _State], remaining: set[int]) -> set[Sdf.Path]:
        """Attributes of ``remaining`` fixes left without an authored value, not yet
        blocked: a rule that wants no authored opinion (not even the fallback)."""
        unauthored = {p for p, s in todo.items() if s.key[0] == "attr" and not s.key[-1]}
        return {p for i in remaining for p in self.owned[i] & unauthored} - self.blocked

    def _reason(self, index: int, wrong: set[Sdf.Path]) -> str:
        bad = sorted(self.owned[index] & wrong)
        if not bad:
            return (
                "its finding remains on the stage with the overrides (an override cannot remove "
                "an opinion of a weaker layer); use --fix"
            )
        first = bad[0]
        if self.fixed.get(first, _absent(first)).key[0] == "absent" and not first.IsPropertyPath():
            return f"it removes or moves <{first}>, which an override cannot do; use --fix"
        return f"its effect on <{first}> cannot be written as an override; use --fix"

    def _report(self, todo: dict[Sdf.Path, _State]) -> None:
        """The outcomes: dropped fixes with their reason; fixes the overlay already
        held are not reported (nothing to do); the rest point at the overlay."""
        shown = layer_real_path(self.overlay.layer) or self.overlay.path
        start = self.overlay.start.pseudoRoot
        meta_changed = any(
            not start.HasInfo(key) or start.GetInfo(key) != value
            for key, value in self.fixed_meta.items()
        )
        by_outcome = {a.outcome: i for i, a in enumerate(self.applied)}
        outcomes = []
        for position, outcome in enumerate(self.outcomes):
            index = by_outcome.get(position)
            if index is None:
                outcomes.append(outcome)
                continue
            reason = self.dropped.get(index)
            needed = bool(self.owned[index] & set(todo)) or (
                self.meta_owners[index] and meta_changed
            )
            if reason is None and not needed:
                continue  # the overlay already holds it
            outcomes.append(
                AppliedFix(
                    outcome.file, outcome.code, outcome.path, shown, outcome.description, reason
                )
            )
        self.outcomes = outcomes

    def _save(self) -> None:
        overlay = self.overlay
        if overlay.layer.ExportToString() == overlay.exported or not any(
            o.applied for o in self.outcomes
        ):
            return
        if self.before_writing is not None:
            self.before_writing()
        try:
            overlay.save()
        except (ChangedOnDisk, OSError) as exc:
            message = getattr(exc, "strerror", None) or str(exc)
            reason = f"writing {overlay.path} failed: {message}"
            self.outcomes = [
                AppliedFix(o.file, o.code, o.path, o.layer, o.description, reason)
                if o.applied
                else o
                for o in self.outcomes
            ]
            self.errors.append(f"{display_path(overlay.path)}: not written: {message}")


def _finding_key(finding: Finding) -> tuple[str, str | None, str]:
    return (finding.code, finding.location.path, finding.message)


def _add_sublayer(layer: Sdf.Layer, root_path: str) -> None:
    """Make ``layer`` sublayer the stage's root layer (relative to itself)."""
    folder = os.path.dirname(layer_real_path(layer) or os.path.abspath(layer_identifier(layer)))
    for existing in layer.subLayerPaths:
        resolved = existing if os.path.isabs(existing) else os.path.join(folder, existing)
        if os.path.realpath(resolved) == os.path.realpath(root_path):
            return
    try:
        relative = os.path.relpath(root_path, folder)
    except ValueError:  # another drive (Windows)
        relative = root_path
    layer.subLayerPaths.append(relative.replace(os.sep, "/"))


def _set_metadata(layer: Sdf.Layer, metadata: dict[str, object]) -> None:
    pseudo_root = layer.pseudoRoot
    for key, value in metadata.items():
        if not pseudo_root.HasInfo(key) or pseudo_root.GetInfo(key) != value:
            pseudo_root.SetInfo(key, value)


def _stage_metadata(root: Sdf.Layer) -> dict[str, object]:
    pseudo_root = root.pseudoRoot
    return {
        key: pseudo_root.GetInfo(key)
        for key in pseudo_root.ListInfoKeys()
        if key not in _NOT_STAGE_METADATA
    }


def _snapshot(layer: Sdf.Layer) -> Sdf.Layer:
    copy = Sdf.Layer.CreateAnonymous(".usda")
    copy.TransferContent(layer)
    return copy


# -- composed state ------------------------------------------------------------------------


@record(frozen=True)
class _State:
    """A prim or property as a consumer sees it, comparable by value; ``payload``
    is what :func:`_author` needs to write it (kept out of comparisons)."""

    key: tuple
    payload: Any = field(default=None, compare=False)


_NO_VALUE = _State(("value", None))
_ABSENT = _State(("absent",))


def _absent(path: Sdf.Path) -> _State:
    return _NO_VALUE if path.IsPropertyPath() else _ABSENT


def composed_stage(stage: Usd.Stage) -> dict[str, object]:
    """What ``--fix-to`` reproduces of the stage ``--fix`` gives: the stage
    metadata, the order of root prims, and each prim a traversal sees and its
    properties, as consumers read them (comparable with ``==``). A property
    with no value, targets or connections reads as one that is not there (an
    override cannot remove a weaker layer's declaration)."""
    pseudo_root = stage.GetPseudoRoot()
    states = _capture(stage, [child.GetPath() for child in pseudo_root.GetChildren()])
    return {
        "metadata": _stage_metadata(stage.GetRootLayer()),
        "root prims": _child_names(pseudo_root),
        "objects": {
            str(path): state.key
            for path, state in states.items()
            if state != _ABSENT and not (path.IsPropertyPath() and state == _NO_VALUE)
        },
    }


def _capture(stage: Usd.Stage, paths: Iterable[Sdf.Path]) -> dict[Sdf.Path, _State]:
    states: dict[Sdf.Path, _State] = {}
    for path in paths:
        if path == Sdf.Path.absoluteRootPath:
            continue
        if path.IsPropertyPath():
            prop_path = path.GetParentPath() if path.IsTargetPath() else path
            states[prop_path] = _property_state(stage.GetPropertyAtPath(prop_path))
            continue
        prim = stage.GetPrimAtPath(path)
        states[path] = _prim_state(prim)
        if not prim or not prim.IsActive():
            continue
        for descendant in Usd.PrimRange(prim, Usd.PrimAllPrimsPredicate):
            states[descendant.GetPath()] = _prim_state(descendant)
            if descendant.IsActive():  # an inactive prim's properties count for nothing
                for prop in descendant.GetProperties():
                    states[prop.GetPath()] = _property_state(prop)
    return states


def _prim_state(prim: Usd.Prim) -> _State:
    """Type, definition, applied schemas and customData (as leaf key paths:
    dictionaries compose key by key, so a stronger layer sets a leaf, never
    removes it). An inactive prim is as good as absent: no traversal sees it."""
    if not prim or not prim.IsActive():
        return _ABSENT
    leaves = dict(_leaves(prim.GetCustomData()))
    schemas = tuple(prim.GetAppliedSchemas())
    children = _child_names(prim)
    key = (
        "prim",
        prim.GetTypeName(),
        prim.IsDefined(),
        schemas,
        tuple(sorted((name, repr(value)) for name, value in leaves.items())),
        children,
    )
    return _State(key, (leaves, schemas))


def _child_names(prim: Usd.Prim) -> tuple[str, ...]:
    """The children a traversal sees, in order."""
    return tuple(child.GetName() for child in prim.GetChildren())


def _leaves(dictionary: dict, prefix: str = ""):
    for name, value in dictionary.items():
        if isinstance(value, dict) and value:
            yield from _leaves(value, f"{prefix}{name}:")
        else:
            yield f"{prefix}{name}", value


def _property_state(prop: Usd.Property | None) -> _State:
    """A relationship's targets; an attribute's type, resolved values (as
    ``Usd.AttributeQuery`` resolves them: a blocked attribute resolves to its
    fallback, like one without opinions) and whether it has an authored value
    (a rule may want one, like CA006, or none, like SE007)."""
    if isinstance(prop, Usd.Relationship) and prop:
        targets = tuple(prop.GetTargets())
        return _State(("rel", tuple(map(str, targets))), targets) if targets else _NO_VALUE
    if isinstance(prop, Usd.Attribute) and prop:
        default = Usd.AttributeQuery(prop).Get(Usd.TimeCode.Default())
        samples = tuple((time, prop.Get(time)) for time in prop.GetTimeSamples())
        # A weaker mistyped spec stays an SE016 finding although a stronger one hides it.
        mistyped = bool(mismatched_specs(prop))
        # Connections count too (RM003 turns them into a relationship's targets).
        sources = tuple(prop.GetConnections()) if prop.HasAuthoredConnections() else ()
        if default is None and not samples and not mistyped and not sources:
            return _NO_VALUE
        authored = prop.HasAuthoredValue()
        key = (
            "attr",
            str(prop.GetTypeName()),
            repr(default),
            repr(samples),
            mistyped,
            tuple(map(str, sources)),
            authored,
        )
        payload = (prop.GetTypeName(), prop.IsCustom(), default, samples, authored, sources)
        return _State(key, payload)
    return _NO_VALUE


def _matches(now: _State, wanted: _State) -> bool:
    """Whether the overlay gives ``wanted``; a removed value written as its
    fallback (so that ``Get()`` returns it) counts, though it is authored."""
    if now == wanted:
        return True
    return (
        now.key[0] == wanted.key[0] == "attr"
        and now.key[:-1] == wanted.key[:-1]
        and not wanted.key[-1]
    )


def _author_all(
    stage: Usd.Stage,
    layer: Sdf.Layer,
    states: dict[Sdf.Path, _State],
    blocked: set[Sdf.Path],
    order: dict[Sdf.Path, int],
) -> None:
    """Author ``states`` into ``layer``: prims before their properties, in the
    fixed stage's order (parents first), then the order of their children."""
    last = len(order)

    def rank(path: Sdf.Path):
        prim = path.GetPrimPath()
        return (path.IsPropertyPath(), order.get(prim, last), prim.pathElementCount, path)

    with Usd.EditContext(stage, Usd.EditTarget(layer)):
        for path in sorted(states, key=rank):
            _author(stage, path, states[path], path in blocked)
        for path, state in states.items():
            if state.key[0] == "prim":
                prim = stage.GetPrimAtPath(path)
                if prim and _child_names(prim) != state.key[-1]:
                    prim.SetChildrenReorder(list(state.key[-1]))


def _author(stage: Usd.Stage, path: Sdf.Path, state: _State, block: bool) -> None:
    """Make the composed ``path`` match ``state`` by authoring in the edit target."""
    if not path.IsPropertyPath():
        _author_prim(stage, path, state)
        return
    prim = stage.GetPrimAtPath(path.GetPrimPath())
    if not prim:
        return  # its prim cannot be brought back: the caller's check reports it
    kind = state.key[0]
    if kind == "rel":
        rel = prim.GetRelationship(path.name) or prim.CreateRelationship(path.name)
        rel.SetTargets(list(state.payload))
    elif kind == "attr":
        _author_attribute(prim, path.name, state, block)
    else:
        _author_no_value(prim, path.name)


def _author_prim(stage: Usd.Stage, path: Sdf.Path, state: _State) -> None:
    prim = stage.GetPrimAtPath(path)
    if state.key[0] == "absent":
        if prim and prim.IsActive():
            prim.SetActive(False)
        return
    _, type_name, defined, schemas, _, _ = state.key
    leaves, _ = state.payload
    if not prim or (not prim.IsDefined() and defined):
        prim = stage.DefinePrim(path, type_name)
    if not prim.IsActive():
        prim.SetActive(True)
    if prim.GetTypeName() != type_name:
        prim.SetTypeName(type_name)
    _author_schemas(prim, schemas)
    _author_custom_data(prim, leaves)


def _author_schemas(prim: Usd.Prim, schemas: tuple[str, ...]) -> None:
    current = prim.GetAppliedSchemas()
    for name in schemas:
        if name not in current:
            prim.AddAppliedSchema(name)
    for name in current:
        if name not in schemas:
            prim.RemoveAppliedSchema(name)


def _author_custom_data(prim: Usd.Prim, leaves: dict[str, object]) -> None:
    now = dict(_leaves(prim.GetCustomData()))
    for name, value in leaves.items():
        if name not in now or repr(now[name]) != repr(value):
            prim.SetCustomDataByKey(name, value)


def _author_attribute(prim: Usd.Prim, name: str, state: _State, block: bool) -> None:
    type_name, custom, default, samples, authored, sources = state.payload
    attr = prim.GetAttribute(name)
    if attr and list(attr.GetConnections()) != list(sources):
        attr.SetConnections(list(sources))  # explicit: weaker connections hidden
    elif sources and not attr:
        attr = prim.CreateAttribute(name, type_name, custom)
        attr.SetConnections(list(sources))
    if not authored and not (attr and attr.HasAuthoredValue()):
        return  # no opinion here either: the same fallback shows
    attr = attr or prim.CreateAttribute(name, type_name, custom)
    attr.Clear()
    if not authored and (block or default is None):
        attr.Block()  # no opinion at all: weaker ones hidden, the fallback shows
    elif default is not None:
        attr.Set(default)  # the value, or the fallback a removal leaves
    for time, value in samples:
        attr.Set(value, time)


def _author_no_value(prim: Usd.Prim, name: str) -> None:
    """The fix removed the property's every opinion: hide the weaker ones."""
    attr = prim.GetAttribute(name)
    if attr and (attr.HasAuthoredValue() or attr.HasAuthoredConnections()):
        if attr.HasAuthoredValue():
            attr.Block()  # the fix removed every value: block the weaker ones
        if attr.HasAuthoredConnections():
            attr.SetConnections([])  # an explicit empty list hides the weaker ones
        return
    rel = prim.GetRelationship(name)
    if rel and rel.HasAuthoredTargets():
        rel.SetTargets([])  # an explicit empty list hides the weaker targets
