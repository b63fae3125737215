"""--variants: lint a file under other variant selections of its render prims.

A defect inside a variant that is not selected is not on the composed stage,
so a normal run cannot see it. The explorer finds the variant sets of every
usable render prim and its ancestors, then lints the stage once per
combination of their variants (the authored selections first), capped because
the combinations multiply. Selections are authored in the session layer of a
stage opened for this and cleared before each combination; nothing is ever
saved, so the user's files are never written.

A finding that appears under the authored selections is reported as it is; one
that appears only under another combination says which selections (those that
differ from the authored ones) in its message, e.g.
``[variant selection: /Render{quality=high}]``.
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace

from pxr import Sdf, Usd

from ..api import Rule
from ..model import FileResult, Finding
from .linter import RENDER_SCHEMAS, Linter
from .locate import locate
from .stage import open_stage

#: Default cap on the variant combinations linted per file.
DEFAULT_MAX_COMBINATIONS = 64


@dataclass(frozen=True)
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
        variant_sets = stage.GetPrimAtPath(path).GetVariantSets()
        for name in variant_sets.GetNames():
            variant_set = variant_sets.GetVariantSet(name)
            authored = variant_set.GetVariantSelection()
            others = [v for v in variant_set.GetVariantNames() if v != authored]
            if others:
                found.append(VariantSetChoice(path, name, (authored, *others)))
    return found


def combination_count(sets: Sequence[VariantSetChoice]) -> int:
    count = 1
    for variant_set in sets:
        count *= len(variant_set.choices)
    return count


def combinations(sets: Sequence[VariantSetChoice], limit: int) -> Iterator[tuple[str, ...]]:
    """At most ``limit`` combinations, the authored selections first."""
    return itertools.islice(itertools.product(*(s.choices for s in sets)), limit)


def describe(sets: Sequence[VariantSetChoice], combination: Sequence[str]) -> str:
    """The selections that differ from the authored ones: ``/Render{quality=high}``."""
    return ", ".join(
        str(s.prim_path.AppendVariantSelection(s.name, variant))
        for s, variant in zip(sets, combination, strict=True)
        if variant != s.authored
    )


def author_selection(
    stage: Usd.Stage, sets: Sequence[VariantSetChoice], combination: Sequence[str]
) -> None:
    """Author ``combination`` in the stage's session layer, replacing the last one."""
    session = stage.GetSessionLayer()
    with Sdf.ChangeBlock():
        session.Clear()
        for variant_set, variant in zip(sets, combination, strict=True):
            if variant != variant_set.authored:
                spec = Sdf.CreatePrimInLayer(session, variant_set.prim_path)
                spec.variantSelections[variant_set.name] = variant


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

    def lint_path(self, path: str) -> FileResult:
        if not os.path.isfile(path):
            return self.linter.lint_path(path)  # it reports what is wrong
        opened = open_stage(path)
        if opened.stage is None:
            return self.linter.lint_path(path)
        return FileResult(path, findings=tuple(self.lint_stage(opened.stage, path)))

    def lint_stage(self, stage: Usd.Stage, file: str | None = None) -> list[Finding]:
        """Findings under every explored combination; the session layer is
        left empty again."""
        sets = render_variant_sets(stage)
        if not sets:
            return self.linter.lint_stage(stage, file)
        seen: dict[tuple, Finding] = {}
        try:
            for combination in combinations(sets, self.max_combinations):
                author_selection(stage, sets, combination)
                selection = describe(sets, combination)
                for finding in self.linter.lint_stage(stage, file):
                    key = (finding.code, finding.location.path, finding.message)
                    if key not in seen:
                        seen[key] = _annotated(stage, finding, selection)
        finally:
            stage.GetSessionLayer().Clear()
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
