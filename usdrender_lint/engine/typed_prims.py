"""The prims of some schema types, found by USD rather than by a Python walk.

The engine hands each rule the prims of the types it asks for, and on a large
stage few prims are of those types (a shot has a dozen render prims among a
hundred thousand meshes). Walking every prim from Python costs about a
microsecond per prim for the iteration and another for ``GetTypeName``; USD
can do the walk itself:

- ``UsdUtils.ComputeUsdStageStats`` counts the prims per type name (one C++
  traversal), so the type names present are known, and a name no schema
  defines (which the engine must report, ST010) sends the caller back to its
  own walk;
- a collection whose ``membershipExpression`` is ``//{isa:T1,T2}`` evaluates
  in C++ over the stage (``Usd.ComputeIncludedPathsFromCollection`` with the
  default predicate, the one ``Stage.Traverse`` uses). A collection must live
  on the stage it evaluates, so an ``over`` holding it is authored in the
  stage's session layer and removed right after; the rules never see it.

The matches come back as a path set and are put back in traversal order
(depth first, children in namespace order).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from pxr import Sdf, Usd

from ..layers.files import layer_real_path
from . import layer_words

#: Below this many prims a Python walk costs less than asking USD (about 2 us
#: a prim against fixed costs of some 15 ms), and below about this many specs
#: in the layers' files it surely has fewer.
MIN_PRIMS = 8000
MIN_SPECS = 5 * MIN_PRIMS
#: The prim holding the query, in the session layer while it runs.
_QUERY_PRIM = Sdf.Path("/__usdrender_lint_type_query")
_QUERY_ATTR = "collection:types:membershipExpression"
#: ComputeUsdStageStats's name for typeless prims (a type of that name would hide there).
_UNTYPED = "untyped"


def type_counts(stage: Usd.Stage) -> tuple[dict[str, int], int]:
    """Prims per type name (instance prototypes included) and the prim count."""
    from pxr import UsdUtils  # its import costs a start-up; only large stages need it

    stats = UsdUtils.ComputeUsdStageStats(stage)
    counts: dict[str, int] = {}
    for part in ("primary", "prototypes"):
        for name, count in stats.get(part, {}).get("primCountsByType", {}).items():
            counts[name] = counts.get(name, 0) + count
    return counts, int(stats.get("totalPrimCount", 0))


def find(
    stage: Usd.Stage, wanted: Callable[[str], bool], unknown: Iterable[str]
) -> list[Usd.Prim] | None:
    """The usable prims (``stage.Traverse()``'s) whose type name ``wanted``
    accepts, in traversal order; None when the caller must walk the stage
    itself: a small stage, a type name in ``unknown`` (no schema defines it)
    present, a session layer that holds more than variant selections (the
    query is authored beside them)."""
    session = stage.GetSessionLayer()
    if not _may_query(stage, session):
        return None
    names = _type_names(stage)
    if names is None:
        return None
    chosen = [name for name in names if wanted(name)]
    # Only now: asking ``wanted`` about a name no schema defines is what adds it to ``unknown``.
    if not set(unknown).isdisjoint(names):
        return None
    if not chosen:
        return []
    paths = _evaluate(stage, session, chosen)
    prims = [stage.GetPrimAtPath(path) for path in paths]
    return sorted(prims, key=traversal_key(stage))


def _may_query(stage: Usd.Stage, session: Sdf.Layer | None) -> bool:
    """Whether the query can be authored in the session layer (an anonymous one
    that holds variant selections at most) and the stage may be large."""
    if session is None or not session.anonymous:
        return False
    if session.rootPrims and not layer_words.holds_only_selections(session):
        return False
    # Known small without asking USD (whose stats cost an import).
    return _spec_estimate(stage) >= MIN_SPECS


def _type_names(stage: Usd.Stage) -> list[str] | None:
    """The type names of a large stage's prims; None for a small stage, or one
    where a prim typed ``untyped`` would be counted with the typeless ones."""
    counts, total = type_counts(stage)
    if total < MIN_PRIMS:
        return None
    if layer_words.layers_may_hold(stage.GetUsedLayers(), _UNTYPED):
        return None
    return [name for name in counts if name != _UNTYPED]


def _spec_estimate(stage: Usd.Stage) -> int:
    """The specs of the stage's layers, from their files (layer_words.spec_count);
    a layer that cannot say counts as large."""
    total = 0
    for layer in stage.GetUsedLayers():
        if layer.anonymous:
            continue
        path = layer_real_path(layer)
        count = layer_words.spec_count(path) if path else None
        if count is None:
            return MIN_SPECS
        total += count
    return total


def _evaluate(stage: Usd.Stage, session: Sdf.Layer, type_names: list[str]) -> list[Sdf.Path]:
    expression = Sdf.PathExpression("//{isa:" + ",".join(type_names) + "}")
    with Sdf.ChangeBlock():
        spec = Sdf.CreatePrimInLayer(session, _QUERY_PRIM)
        spec.specifier = Sdf.SpecifierOver
        attr = Sdf.AttributeSpec(
            spec, _QUERY_ATTR, Sdf.ValueTypeNames.PathExpression, Sdf.VariabilityUniform
        )
        attr.default = expression
    try:
        collection = Usd.CollectionAPI(stage.GetPrimAtPath(_QUERY_PRIM), "types")
        query = collection.ComputeMembershipQuery()
        return list(Usd.ComputeIncludedPathsFromCollection(query, stage))
    finally:
        del session.rootPrims[_QUERY_PRIM.name]


def traversal_key(stage: Usd.Stage) -> Callable[[Usd.Prim], tuple[int, ...]]:
    """A sort key giving depth-first order with children in namespace order."""
    positions: dict[Sdf.Path, dict[str, int]] = {}

    def position(path: Sdf.Path) -> int:
        parent = path.GetParentPath()
        if parent not in positions:
            names = stage.GetPrimAtPath(parent).GetChildrenNames()
            positions[parent] = {name: index for index, name in enumerate(names)}
        return positions[parent].get(path.name, -1)

    def key(prim: Usd.Prim) -> tuple[int, ...]:
        return tuple(position(p) for p in prim.GetPath().GetPrefixes())

    return key


__all__ = ["MIN_PRIMS", "find", "traversal_key", "type_counts"]
