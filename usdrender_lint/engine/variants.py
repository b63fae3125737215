"""--variants: lint a file under other variant selections of its render prims.

A defect inside a variant that is not selected is not on the composed stage,
so a normal run cannot see it. The explorer finds the variant sets of every
usable render prim and its ancestors, then lints the stage once per
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
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import replace

from pxr import Sdf, Usd

from ..api import Rule
from ..layers.crate import crate_structure_problem
from ..layers.files import unreadable_reason
from ..model import FileResult, Finding
from ..records import record
from .linter import RENDER_SCHEMAS, Linter
from .locate import locate
from .stage import open_stage

#: Default cap on the variant combinations linted per file.
DEFAULT_MAX_COMBINATIONS = 64


@record(frozen=True)
class VariantSetChoice:
    """A variant set on a prim: its variants, the authored selection first."""

    prim_path: Sdf.Path
    name: str
    #: The authored selection ("" when none is authored), then the other variants.
    choices: tuple[str, ...]

    @property
    def authored(self) -> str:
        return self.choices[0]


def render_variant_sets(stage: Usd.Stage) -> list[VariantSetChoice]:
    """The variant sets of the usable render prims and their ancestors, by path."""
    owners: set[Sdf.Path] = set()
    for prim in stage.Traverse():
        if any(prim.IsA(schema) for schema in RENDER_SCHEMAS):
            while prim and not prim.IsPseudoRoot() and prim.GetPath() not in owners:
                owners.add(prim.GetPath())
                prim = prim.GetParent()
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
    return found


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
    count = 1
    for variant_set in sets:
        count *= len(variant_set.choices)
    return count


def combinations(sets: Sequence[VariantSetChoice], limit: int) -> Iterator[Combination]:
    """At most ``limit`` combinations: the authored selections, then each other
    variant of each set alone, then the rest in product order."""
    if limit < 1:
        return
    yield ()
    produced = 1
    for index, variant_set in enumerate(sets):
        for variant in variant_set.choices[1:]:
            if produced >= limit:
                return
            yield ((index, variant),)
            produced += 1
    for choices in itertools.product(*(range(len(s.choices)) for s in sets)):
        if produced >= limit:
            return
        changes = tuple((i, sets[i].choices[c]) for i, c in enumerate(choices) if c)
        if len(changes) > 1:  # none or one: yielded above
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
    with Sdf.ChangeBlock():
        session.Clear()
        for index, variant in combination:
            spec = Sdf.CreatePrimInLayer(session, sets[index].prim_path)
            spec.variantSelections[sets[index].name] = variant


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
    def rules(self) -> tuple[Rule, ...]:
        return self.linter.rules

    @property
    def raise_errors(self) -> bool:
        return self.linter.raise_errors

    def recording_reads(self):
        """The wrapped linter's :meth:`Linter.recording_reads` (every combination's reads)."""
        return self.linter.recording_reads()

    def lint_path(self, path: str, *, full_composition: bool = False) -> FileResult:
        """Lint ``path`` under each combination; the stage is always composed
        whole (``full_composition`` is accepted, as by Linter.lint_path). The
        result's notes say how many combinations the cap skipped."""
        if unreadable_reason(path) is not None or crate_structure_problem(path) is not None:
            return self.linter.lint_path(path)  # it reports what is wrong
        opened = open_stage(path)
        if opened.stage is None:
            return self.linter.lint_path(path)
        notes: list[str] = []
        findings = self.lint_stage(opened.stage, path, notes)
        return FileResult(path, findings=tuple(findings), notes=tuple(notes))

    def lint_stage(
        self,
        stage: Usd.Stage,
        file: str | None = None,
        notes: list[str] | None = None,
        *,
        texts: Mapping[str, str] | None = None,
    ) -> list[Finding]:
        """Findings under every explored combination; the session layer is
        left empty again. When the cap cut combinations, a line saying how
        many is added to ``notes``. ``texts``: as for :meth:`Linter.lint_stage`."""
        sets = render_variant_sets(stage)
        if not sets:
            return self.linter.lint_stage(stage, file, texts=texts)
        seen: dict[tuple, Finding] = {}
        linted = 0
        try:
            for combination in combinations(sets, self.max_combinations):
                author_selection(stage, sets, combination)
                selection = describe(sets, combination)
                for finding in self.linter.lint_stage(stage, file, texts=texts):
                    key = (finding.code, finding.location.path, finding.message)
                    if key not in seen:
                        seen[key] = _annotated(stage, finding, selection)
                linted += 1
        finally:
            stage.GetSessionLayer().Clear()
        total = combination_count(sets)
        if notes is not None and linted < total:
            notes.append(skipped_note(file or stage.GetRootLayer().identifier, linted, total))
        return sorted(seen.values(), key=Finding.sort_key)


def _annotated(stage: Usd.Stage, finding: Finding, selection: str) -> Finding:
    """The finding with the selection in its message, located outside the
    session layer (which holds only the selections)."""
    if not selection:
        return finding
    session = stage.GetSessionLayer()
    location = finding.location
    if location.path and location.layer == session.identifier:
        prim = stage.GetPrimAtPath(location.path)
        specs = [s for s in prim.GetPrimStack() if s.layer != session] if prim else []
        if specs:
            location = locate(stage, location.file, prim, specs[0].layer)
    return replace(
        finding, message=f"{finding.message} [variant selection: {selection}]", location=location
    )


__all__ = [
    "DEFAULT_MAX_COMBINATIONS",
    "VariantExplorer",
    "VariantSetChoice",
    "combination_count",
    "render_variant_sets",
]
