"""Helpers shared by the PA (RenderPass) rules: the inputPasses
dependency graph and its cycles, the four built-in collections and what their
includes, excludes and membership expressions point at."""

from __future__ import annotations

from collections.abc import Hashable, Iterator, Mapping, Sequence
from typing import Any, Protocol, TypeVar

from pxr import Sdf, Tf, Usd

from usdrender_lint.api import Context, schemas
from usdrender_lint.api.resolve import (
    prim_values,
    typed_target_problem,
    unusable_reason,
)

#: The CollectionAPI instances the RenderPass schema applies (schema.usda).
PASS_COLLECTIONS = ("renderVisibility", "cameraVisibility", "prune", "matte")


class _GraphNode(Hashable, Protocol):
    """What find_cycles needs of a node: a set member with an order (to sort and rotate)."""

    def __lt__(self, other: Any, /) -> bool: ...


Node = TypeVar("Node", bound=_GraphNode)


def usd_error_text(exc: Tf.ErrorException) -> str:
    """The commentary of each Tf error carried by the exception, without the
    C++ function and file names."""
    texts = [str(getattr(arg, "commentary", arg)).strip() for arg in exc.args]
    return "; ".join(t for t in texts if t) or "USD reported an error"


# -- inputPasses ------------------------------------------------------------


def input_pass_graph(ctx: Context) -> dict[Sdf.Path, list[Sdf.Path]]:
    """Each usable RenderPass -> the passes its ``inputPasses`` validly target
    (forwarded; PA002 reports the others). Computed once per stage."""
    return ctx.cached(_input_pass_graph)


def _input_pass_graph(ctx: Context) -> dict[Sdf.Path, list[Sdf.Path]]:
    graph: dict[Sdf.Path, list[Sdf.Path]] = {}
    for prim in ctx.prims_of(schemas.RenderPass):
        graph[prim_values(prim).path] = [
            t.path
            for t in prim_values(prim).targets("inputPasses")
            if typed_target_problem(t, schemas.RenderPass, "a RenderPass") is None
        ]
    return graph


def _rotated_to_smallest(cycle: Sequence[Node]) -> tuple[Node, ...]:
    start = cycle.index(min(cycle))
    return (*cycle[start:], *cycle[:start])


def find_cycles(graph: Mapping[Node, Sequence[Node]]) -> list[tuple[Node, ...]]:
    """The cycle closed by each back edge of a depth-first search (a self-loop
    included), each reported once, rotated to start at its smallest node.

    Nodes are visited in sorted order and edges in their given order, so the
    result is deterministic.
    """
    on_stack: set[Node] = set()
    finished: set[Node] = set()
    found: dict[tuple[Node, ...], None] = {}
    for root in sorted(graph):
        if root in finished:
            continue
        trail = [root]
        pending: list[Iterator[Node]] = [iter(graph.get(root, ()))]
        on_stack.add(root)
        while pending:
            for successor in pending[-1]:
                if successor in on_stack:
                    cycle = trail[trail.index(successor) :]
                    found.setdefault(_rotated_to_smallest(cycle), None)
                elif successor not in finished:
                    trail.append(successor)
                    pending.append(iter(graph.get(successor, ())))
                    on_stack.add(successor)
                    break
            else:
                done = trail.pop()
                pending.pop()
                on_stack.discard(done)
                finished.add(done)
    return list(found)


# -- collections ------------------------------------------------------------


def authored_pass_collections(
    prim: Usd.Prim, ctx: Context
) -> tuple[tuple[str, Usd.CollectionAPI], ...]:
    """The pass's collections with at least one authored property (any layer or
    arc), each with its label ("collection:<name>", the prefix of its property
    names). One left to its schema fallbacks validates, computes and has no
    expression or targets, so the collection rules (PA005, PA006, PA008) skip
    it without asking USD."""
    return ctx.cached(_authored_pass_collections, prim)


def _authored_pass_collections(
    ctx: Context, prim: Usd.Prim
) -> tuple[tuple[str, Usd.CollectionAPI], ...]:
    # One read of the authored names instead of a namespace query and a
    # schema object per collection (~18 -> ~8 us a pass). As in
    # GetAuthoredPropertiesInNamespace, "collection:<name>" alone is not in it.
    authored = {
        parts[1]
        for parts in (name.split(":", 2) for name in prim_values(prim).authored_names())
        if len(parts) == 3 and parts[0] == "collection"
    }
    # The label is made from the name here, once: asking a collection its name
    # is a call into USD, and each collection rule needs the label.
    return tuple(
        (f"collection:{name}", Usd.CollectionAPI(prim, name))
        for name in PASS_COLLECTIONS
        if name in authored
    )


def collection_label(collection: Usd.CollectionAPI) -> str:
    return f"collection:{Usd.CollectionAPI.GetName(collection)}"


def missing_expression_references(
    collection: Usd.CollectionAPI, expression: Sdf.PathExpression
) -> list[Sdf.Path]:
    """Collection paths that ``%/path:name`` references in the expression name
    but that do not exist. usd-core only warns and substitutes an empty
    expression. ``%:name`` means a collection on the owning prim; ``%_`` (the
    weaker expression) is not a reference to a collection."""
    prim = collection.GetPrim()
    stage = prim.GetStage()
    references: list[Sdf.PathExpression.ExpressionReference] = []
    expression.Walk(lambda *_: None, references.append, lambda *_: None)
    missing = []
    for reference in references:
        if reference == Sdf.PathExpression.ExpressionReference.Weaker():
            continue
        owner = reference.path if not reference.path.isEmpty else prim.GetPath()
        owner = owner.MakeAbsolutePath(prim.GetPath())
        target_prim = stage.GetPrimAtPath(owner)
        if not target_prim or not target_prim.HasAPI(Usd.CollectionAPI, reference.name):
            missing.append(owner.AppendProperty(f"collection:{reference.name}"))
    return missing


def dangling_object_reason(ctx: Context, path: Sdf.Path) -> str | None:
    """Why a collection include/exclude target names nothing renderable: no
    object at the path, or a prim that is inactive, ``over``-only or abstract.
    None for an existing property or a usable prim. Asked once per lint and
    path: a stage's passes mostly include the same few prims."""
    return ctx.cached(_dangling_object_reason, path)


def _dangling_object_reason(ctx: Context, path: Sdf.Path) -> str | None:
    stage = ctx.stage
    obj = stage.GetObjectAtPath(path)
    if obj:
        return unusable_reason(obj) if isinstance(obj, Usd.Prim) else None
    # Descendants of an inactive prim are not composed at all: say why.
    start = path.GetPrimPath() if path.IsPropertyPath() else path.GetParentPath()
    for ancestor in reversed(start.GetPrefixes()):
        prim = stage.GetPrimAtPath(ancestor)
        if prim:
            if not prim.IsActive():
                return (
                    f"does not exist on the composed stage (its ancestor <{ancestor}> is inactive)"
                )
            break
    return "does not exist on the composed stage"
