"""--variants: lint a file under other variant selections of its render prims.

A defect inside a variant that is not selected is not on the composed stage,
so a normal run cannot see it. The explorer finds the variant sets of every
usable render prim and its ancestors, and of every prim with a variant that
defines a render prim (one the authored selections leave out), and the sets
nested in a variant the authored selections leave out, then lints the stage once per
combination of their variants, capped because the combinations multiply: the
authored selections first, then each other variant of each set alone (so that
a cap reaches every set it can, and a finding names the one selection behind
it), then the other combinations in order. A combination is the selections
that differ from the authored ones, so its cost does not grow with the number
of sets; how many combinations the cap left out is reported. Selections are
authored in the session layer of a stage opened for this and cleared before
each combination; nothing is ever saved, so the user's files are never
written.

A finding that appears under the authored selections is reported as it is; one
that appears only under another combination says which selections (those that
differ from the authored ones) in its message, e.g.
``[variant selection: /Render{quality=high}]``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import replace
from typing import Any

from pxr import Sdf, Tf, Usd

from ..api import Fix
from ..layers.files import real_path, unreadable_reason
from ..model import VARIANT_SELECTION_NOTE, FileResult, Finding
from ..records import record
from . import layer_words
from .assets import Reads
from .linter import RENDER_SCHEMAS, Linter, LintRun, unsafe_to_open
from .locate import locate
from .stage import open_stage
from .suppress import UNUSED_SUPPRESSION_CODE
from .typed_prims import traversal_key

#: Default cap on the variant combinations linted per file.
DEFAULT_MAX_COMBINATIONS = 64


@record(frozen=True)
class VariantSetChoice:
    """A variant set on a prim: its variants, the authored selection first."""

    prim_path: Sdf.Path
    name: str
    #: The authored selection ("" when none is authored), then the other variants.
    choices: tuple[str, ...]
    #: For a set that only another selection of the prim's sets composes (one
    #: nested in an unselected variant): those (set name, variant) selections.
    within: tuple[tuple[str, str], ...] = ()

    @property
    def authored(self) -> str:
        return self.choices[0]


def render_variant_sets(
    stage: Usd.Stage, prims: Iterable[Usd.Prim] | None = None
) -> list[VariantSetChoice]:
    """The variant sets of the usable render prims (of ``prims`` when given,
    else of the stage) and their ancestors, by path."""
    owners: set[Sdf.Path] = set()
    for prim in stage.Traverse() if prims is None else prims:
        if any(prim.IsA(schema) for schema in RENDER_SCHEMAS):
            while prim and not prim.IsPseudoRoot() and prim.GetPath() not in owners:
                owners.add(prim.GetPath())
                prim = prim.GetParent()
    owners |= _owners_of_variant_render_prims(stage)
    found = []
    for path in sorted(owners):
        prim = stage.GetPrimAtPath(path)
        names = prim.GetVariantSets().GetNames()
        if not names:
            continue
        selections = prim.GetVariantSets().GetAllVariantSelections()
        variants = _variant_names(prim)
        for name in names:
            authored = selections.get(name, "")
            others = [v for v in variants.get(name, ()) if v != authored]
            if others:
                found.append(VariantSetChoice(path, name, (authored, *others)))
        found.extend(_nested_sets(prim, set(names), selections))
    return found


def _nested_sets(
    prim: Usd.Prim, composed: set[str], selections: Mapping[str, str]
) -> list[VariantSetChoice]:
    """The variant sets of ``prim`` that a variant the authored selections
    leave out holds (``{quality=high}{detail=b}``), read from its specs: the
    stage as composed has no such set, so only selecting the outer variant
    lets their variants be explored. Each says the selections it is within."""
    found: dict[str, VariantSetChoice] = {}
    pending: list[tuple[Sdf.PrimSpec, tuple[tuple[str, str], ...]]] = [
        (spec, ()) for spec in prim.GetPrimStack()
    ]
    while pending:
        spec, within = pending.pop()
        for name, variant_set in spec.variantSets.items():
            for variant_name, variant in variant_set.variants.items():
                inner = variant.primSpec
                if within or (name in composed and variant_name != selections.get(name, "")):
                    pending.append((inner, (*within, (name, variant_name))))
            if within and name not in composed and name not in found:
                authored = selections.get(name) or spec.variantSelections.get(name, "")
                names = variant_set.variants.keys()  # noqa: SIM118 - iterating gives specs
                others = sorted(v for v in names if v != authored)
                if others:
                    found[name] = VariantSetChoice(
                        prim.GetPath(), name, (authored, *others), within
                    )
    return list(found.values())


def _owners_of_variant_render_prims(stage: Usd.Stage) -> set[Sdf.Path]:
    """The prims on ``stage`` with a variant set that, in the root layer
    stack, holds a variant defining a render prim (typed so in the variant):
    a variant that adds the render settings is not above a render prim of the
    authored selections, yet selecting it changes what renders. Only prims
    with variant sets are looked into (their root layer stack specs' variants),
    and none when no layer of the root layer stack authors a variant set."""
    layers = stage.GetLayerStack(includeSessionLayers=False)
    if not layer_words.layers_may_hold(layers, "variantSetChildren"):
        return set()
    render_types = {Usd.SchemaRegistry.GetSchemaTypeName(s) for s in RENDER_SCHEMAS}
    in_root_stack = set(layers)
    owners: set[Sdf.Path] = set()
    for prim in stage.TraverseAll():
        if not prim.HasVariantSets():
            continue
        for spec in prim.GetPrimStack():
            if spec.layer in in_root_stack and _variants_define(spec, render_types):
                owners.add(prim.GetPath())
                break
    return owners


def _variants_define(spec: Sdf.PrimSpec, type_names: set[str]) -> bool:
    """Whether a variant of ``spec``'s variant sets defines, at any depth
    (nested variants too), a prim spec of one of ``type_names``."""
    pending = [
        variant.primSpec
        for variant_set in spec.variantSets.values()
        for variant in variant_set.variants.values()
    ]
    while pending:
        inner = pending.pop()
        for child in inner.nameChildren.values():
            if child.typeName in type_names:
                return True
            pending.append(child)
        pending.extend(
            variant.primSpec
            for variant_set in inner.variantSets.values()
            for variant in variant_set.variants.values()
        )
    return False


def _variant_names(prim: Usd.Prim) -> dict[str, list[str]]:
    """Every variant set's variants, sorted, as UsdVariantSet.GetVariantNames
    gives them (the variants its specs in the prim's stack define), read in
    one pass over the stack: that call walks the whole prim index for each
    set, so a prim with 10,000 sets cost 10,000 walks."""
    variants: dict[str, set[str]] = {}
    for spec in prim.GetPrimStack():
        for name, variant_set in spec.variantSets.items():
            variants.setdefault(name, set()).update(variant_set.variants.keys())
    return {name: sorted(found) for name, found in variants.items()}


#: A combination: the (index of the set, variant) selections that differ
#: from the authored ones; () is the authored selections.
Combination = tuple[tuple[int, str], ...]


def combination_count(sets: Sequence[VariantSetChoice]) -> int:
    """How many combinations there are: a set nested in a variant counts only
    with that variant selected."""
    within = _within(sets)
    nested: dict[Combination, list[int]] = {}
    for index, outer in enumerate(within):
        if outer:
            nested.setdefault(outer[-1:], []).append(index)

    def count(index: int) -> int:
        total = 1  # the authored selection
        for variant in sets[index].choices[1:]:
            inner = 1
            for child in nested.get(((index, variant),), ()):
                inner *= count(child)
            total += inner
        return total

    result = 1
    for index, outer in enumerate(within):
        if not outer:
            result *= count(index)
    return result


def _within(sets: Sequence[VariantSetChoice]) -> list[Combination]:
    """Each set's ``within`` as (index, variant) selections, by index."""
    index_of = {(s.prim_path, s.name): i for i, s in enumerate(sets)}
    return [
        tuple(sorted((index_of[(s.prim_path, name)], variant) for name, variant in s.within))
        for s in sets
    ]


def combinations(sets: Sequence[VariantSetChoice], limit: int) -> Iterator[Combination]:
    """At most ``limit`` combinations: the authored selections, then each other
    variant of each set alone (a nested set's with the selections it is
    within), then the rest in product order."""
    if limit < 1:
        return
    within = _within(sets)
    yield ()
    produced = 1
    singles = set()
    for index, variant_set in enumerate(sets):
        for variant in variant_set.choices[1:]:
            if produced >= limit:
                return
            single = tuple(sorted((*within[index], (index, variant))))
            singles.add(single)
            yield single
            produced += 1
    for choices in itertools.product(*(range(len(s.choices)) for s in sets)):
        if produced >= limit:
            return
        changes = tuple((i, sets[i].choices[c]) for i, c in enumerate(choices) if c)
        if len(changes) < 2 or changes in singles:  # yielded above
            continue
        chosen = set(changes)
        if any(not chosen.issuperset(within[i]) for i, _ in changes):
            continue  # a nested set's variant without the variant holding it
        yield changes
        produced += 1


def describe(sets: Sequence[VariantSetChoice], combination: Combination) -> str:
    """The selections that differ from the authored ones: ``/Render{quality=high}``."""
    return ", ".join(
        str(sets[index].prim_path.AppendVariantSelection(sets[index].name, variant))
        for index, variant in combination
    )


def author_selection(
    stage: Usd.Stage, sets: Sequence[VariantSetChoice], combination: Combination
) -> None:
    """Author ``combination`` in the stage's session layer, replacing the last one."""
    session = stage.GetSessionLayer()
    # The recomposition reports its errors (a missing reference under this
    # selection) as USD warnings: the lint reports them as findings, not stderr.
    with Tf.DiagnosticTrap() as trap:
        with Sdf.ChangeBlock():
            session.Clear()
            for index, variant in combination:
                spec = Sdf.CreatePrimInLayer(session, sets[index].prim_path)
                spec.variantSelections[sets[index].name] = variant
        trap.Clear()  # before the trap ends, which posts what it still holds


def _clear_selections(stage: Usd.Stage) -> None:
    """The session layer emptied again (its recomposition's warnings trapped)."""
    with Tf.DiagnosticTrap() as trap:
        stage.GetSessionLayer().Clear()
        trap.Clear()


def skipped_note(path: str, linted: int, total: int) -> str:
    """What the cap left out, for the user: how many combinations were not linted."""
    skipped = total - linted
    # 10,000 sets of two variants make 2^10000 combinations: too many digits to print.
    shown = f"{skipped:,}" if skipped < 10**15 else f"about 10^{int(math.log10(skipped))}"
    combinations = "combination" if linted == 1 else "combinations"
    were = "was" if skipped == 1 else "were"
    return (
        f"{path}: --variants linted {linted:,} variant {combinations}; {shown} more {were} "
        "skipped (raise --max-variant-combinations)"
    )


class VariantExplorer:
    """Lints files like :class:`Linter` (same ``lint_path``), under each
    variant combination of their render prims, at most ``max_combinations``."""

    def __init__(self, linter: Linter, max_combinations: int = DEFAULT_MAX_COMBINATIONS) -> None:
        if max_combinations < 1:
            raise ValueError(f"max_combinations must be at least 1, got {max_combinations}")
        self.linter = linter
        self.max_combinations = max_combinations

    @property
    def raise_errors(self) -> bool:
        return self.linter.raise_errors

    def lint_path(self, path: str, *, full_composition: bool = False) -> FileResult:
        """Lint ``path`` under each combination (:meth:`run_path`'s result)."""
        return self.run_path(path, full_composition=full_composition).result

    def run_path(
        self, path: str, *, full_composition: bool = False, reads: bool = False
    ) -> LintRun[Any]:
        """Lint ``path`` under each combination; the stage is always composed
        whole (``full_composition`` is accepted, as by Linter.run_path). The
        result's notes say how many combinations the cap skipped; ``reads``
        records what every combination's lint read."""
        if unreadable_reason(path) or unsafe_to_open(path):
            return self.linter.run_path(path, reads=reads)  # it reports what is wrong
        opened = open_stage(path)
        if opened.stage is None:
            return self.linter.run_path(path, reads=reads)
        return self._run_stage(opened.stage, path, own_stage=True, reads=reads)

    def lint_stage(
        self, stage: Usd.Stage, file: str | None = None, *, texts: Mapping[str, str] | None = None
    ) -> list[Finding]:
        """The findings of :meth:`run_stage`."""
        return list(self.run_stage(stage, file, texts=texts).findings)

    def run_stage(
        self, stage: Usd.Stage, file: str | None = None, *, texts: Mapping[str, str] | None = None
    ) -> LintRun[Any]:
        """Findings under every explored combination; the session layer is
        left empty again. When the cap cut combinations, the result has a
        note saying how many. ``texts``: as for :meth:`Linter.run_stage`."""
        return self._run_stage(stage, file, texts=texts)

    def _run_stage(
        self,
        stage: Usd.Stage,
        file: str | None,
        own_stage: bool = False,
        texts: Mapping[str, str] | None = None,
        reads: bool = False,
    ) -> LintRun[Any]:
        seen: dict[tuple, Finding] = {}
        #: How many combinations found each unused suppression.
        unused: dict[tuple, int] = {}
        fixes: dict[Finding, Fix] = {}
        origins: dict[Finding, tuple[str, Sdf.Path | None]] = {}
        recorded = Reads() if reads else None
        linted = 0
        #: False when a combination's lint stopped part way (a corrupt layer):
        #: what it read is not known in full, so the result is not cached.
        completed = True
        lint = self.linter.run_stage
        with _Walk(self.linter, stage, own_stage) as walk:
            sets = render_variant_sets(stage, walk.prims())
            if not sets:
                return lint(stage, file, texts=texts, prims=walk.prims(), reads=reads)
            errors = _CompositionErrors(stage, walk)
            try:
                for combination in combinations(sets, self.max_combinations):
                    author_selection(stage, sets, combination)
                    selection = describe(sets, combination)
                    run = lint(
                        stage,
                        file,
                        texts=texts,
                        prims=walk.prims(),
                        reads=reads,
                        composition_errors=errors.now,
                    )
                    for finding in run.findings:
                        shown = _annotated(stage, finding, selection)
                        # One finding per place: the same problem authored in two
                        # variants (two lines, two layers) is two findings.
                        at = shown.location
                        key = (finding.code, at.path, finding.message, at.layer, at.line, at.column)
                        if finding.code == UNUSED_SUPPRESSION_CODE:
                            unused[key] = unused.get(key, 0) + 1
                        if key not in seen:
                            seen[key] = shown
                            origins[shown] = run.origin(finding)
                            if finding in run.fixes and shown is finding:
                                fixes[shown] = run.fixes[finding]
                    if recorded is not None and run.reads is not None:
                        recorded.merge(run.reads)
                    completed = completed and run.completed
                    linted += 1
            finally:
                _clear_selections(stage)
        # A suppression is unused only when no combination used it.
        for key, count in unused.items():
            if count < linted:
                del seen[key]
        total = combination_count(sets)
        name = file or stage.GetRootLayer().identifier
        notes = (skipped_note(name, linted, total),) if linted < total else ()
        findings = tuple(sorted(seen.values(), key=Finding.sort_key))
        result = FileResult(file or real_path(stage.GetRootLayer()), findings=findings, notes=notes)
        return LintRun(result, fixes, origins, recorded, "full", completed=completed)


class _Walk:
    """The prims the linter's walk keeps (:meth:`Linter.walk_candidates`),
    kept up to date across combinations without walking the stage again: a
    change of the session layer's selections makes USD recompose some prims
    and their descendants (ObjectsChanged's resynced paths, which include the
    prims that reach a changed one through an arc), and only those subtrees
    are walked again; every other prim is composed as before."""

    def __init__(self, linter: Linter, stage: Usd.Stage, own_stage: bool) -> None:
        self._linter = linter
        self._stage = stage
        self._own_stage = own_stage
        #: Where USD recomposed since ``_paths`` was walked.
        self._changed: set[Sdf.Path] = set()
        self._paths: list[Sdf.Path] = []
        self._listener: Any = None

    def __enter__(self) -> _Walk:
        prims = self._linter.walk_candidates(self._stage, own_stage=self._own_stage)
        self._paths = [p.GetPath() for p in prims]
        # From here on every edit of the stage is a combination's.
        self._listener = Tf.Notice.Register(Usd.Notice.ObjectsChanged, self._note, self._stage)
        return self

    def __exit__(self, *exc: object) -> None:
        self._listener.Revoke()

    def _note(self, notice: Usd.Notice.ObjectsChanged, stage: Usd.Stage) -> None:
        self._changed.update(p.GetPrimPath() for p in notice.GetResyncedPaths())
        self._changed.update(p.GetPrimPath() for p in notice.GetChangedInfoOnlyPaths())

    def recomposed(self) -> list[Sdf.Path]:
        """The outermost prims USD recomposed since the authored selections
        were walked (every other prim is composed as it was then)."""
        return _outermost(self._changed)

    def prims(self) -> list[Usd.Prim]:
        """The walk's prims on the stage as it is composed now, in traversal order."""
        stage = self._stage
        roots = self.recomposed()
        if Sdf.Path.absoluteRootPath in roots:
            return self._linter.walk_candidates(stage)
        kept = [stage.GetPrimAtPath(p) for p in self._paths if not _under(p, roots)]
        if not roots:
            return kept
        walked = [
            prim
            for root in roots
            for prim in self._linter.walk_candidates(stage, _subtree(stage, root))
        ]
        return sorted([*kept, *walked], key=traversal_key(stage))


class _CompositionErrors:
    """A combination's composition errors without asking the whole stage
    (``GetCompositionErrors`` visits every prim index: 10 ms a combination
    on a 100,000-prim stage): the authored selections' errors, less those of
    the prims USD recomposed since, plus the recomposed prims' own
    (``PcpPrimIndex.localErrors``; UsdStage::GetCompositionErrors gathers
    the layer stack's errors and every prim index's local errors). A
    prototype's errors are its instances' to report, so a stage with
    instances is asked whole."""

    def __init__(self, stage: Usd.Stage, walk: _Walk) -> None:
        self._stage = stage
        self._walk = walk
        self._authored: list | None = None

    def now(self) -> list:
        stage = self._stage
        roots = self._walk.recomposed()
        if not roots:
            if self._authored is None:
                self._authored = list(stage.GetCompositionErrors())
            return list(self._authored)
        authored = self._authored
        if authored is None or Sdf.Path.absoluteRootPath in roots or stage.GetPrototypes():
            return list(stage.GetCompositionErrors())
        kept = []
        for error in authored:
            site = _error_prim(error)
            if site is None:
                return list(stage.GetCompositionErrors())  # whose it is is not known
            if not _under(site, roots):
                kept.append(error)
        for root in roots:
            prim = stage.GetPrimAtPath(root)
            if prim:
                for each in Usd.PrimRange(prim, Usd.PrimAllPrimsPredicate):
                    kept.extend(each.GetPrimIndex().localErrors)
        return kept


def _error_prim(error: Any) -> Sdf.Path | None:
    """The prim whose composition posted ``error`` (its root site's path; the
    absolute root for the layer stack's own), None when it names none."""
    path = getattr(getattr(error, "rootSite", None), "path", None)
    if not isinstance(path, Sdf.Path) or path.isEmpty:
        return None
    return path.GetPrimPath()


def _outermost(paths: set[Sdf.Path]) -> list[Sdf.Path]:
    """``paths`` without those under another of them."""
    return [p for p in paths if not any(p != q and p.HasPrefix(q) for q in paths)]


def _under(path: Sdf.Path, roots: Sequence[Sdf.Path]) -> bool:
    return any(path.HasPrefix(root) for root in roots)


def _subtree(stage: Usd.Stage, root: Sdf.Path) -> Iterable[Usd.Prim]:
    """The prims of ``stage.Traverse()`` at and under ``root``: none when the
    prim there is not one (its flags include its ancestors', as Traverse's
    predicate reads them), or lies in an instance or a prototype."""
    prim = stage.GetPrimAtPath(root)
    if not prim or not Usd.PrimDefaultPredicate(prim):
        return ()
    if prim.IsInstanceProxy() or prim.IsInPrototype() or prim.IsPrototype():
        return ()
    return Usd.PrimRange(prim, Usd.PrimDefaultPredicate)


def _annotated(stage: Usd.Stage, finding: Finding, selection: str) -> Finding:
    """The finding with the selection in its message, located outside the
    session layer (which holds only the selections), and without a fix."""
    if not selection:
        return finding
    session = stage.GetSessionLayer()
    location = finding.location
    if location.path and location.layer == session.identifier:
        prim = stage.GetPrimAtPath(location.path)
        specs = [s for s in prim.GetPrimStack() if s.layer != session] if prim else []
        if specs:
            location = locate(stage, location.file, prim, specs[0].layer)
    # No fix: --fix neither explores variants nor sees what only another selection shows.
    return replace(
        finding,
        message=finding.message + VARIANT_SELECTION_NOTE.format(selection),
        location=location,
        fix=None,
    )


__all__ = [
    "DEFAULT_MAX_COMBINATIONS",
    "VariantExplorer",
    "VariantSetChoice",
    "combination_count",
    "render_variant_sets",
]
