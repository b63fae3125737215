"""``check --shard K/N``: lint one of N deterministic parts of the files, so a
CI matrix of N jobs lints everything once (``usdrender-lint merge`` joins their
JSON reports).

Every job computes the same partition from the same files, whatever the
machine, the checkout's location or the order of the arguments: the files are
ordered by a hash of their path relative to the project root and dealt out to
the shards, so shards differ by at most one file. With config ``roots``, the
unit is a group of root stages that share a changed file (their findings are
narrowed together, running/roots.py) or a changed file linted alone; groups
are dealt out largest first, each to the shard with the fewest files so far.
"""

from __future__ import annotations

import hashlib
import heapq
import os
from collections.abc import Sequence
from pathlib import Path, PurePath
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .roots import ContextPlan


class ShardError(ValueError):
    """A ``--shard`` value that is not ``K/N`` with 1 <= K <= N."""


def parse_shard(text: str) -> tuple[int, int]:
    """``"2/4"`` -> ``(2, 4)``."""
    index, slash, count = text.strip().partition("/")
    try:
        if not slash:
            raise ValueError
        k, n = int(index), int(count)
    except ValueError:
        raise ShardError(f"--shard must be K/N (e.g. 2/4), got {text!r}") from None
    if n < 1 or not 1 <= k <= n:
        raise ShardError(f"--shard {text}: K must be between 1 and N (N >= 1)")
    return k, n


def shard_key(path: str, root: Path) -> str:
    """The hash a file is ordered by: of its path relative to ``root``, with
    ``/`` separators (the same on every machine and checkout location). A name
    that is not UTF-8 is hashed as the bytes it has on disk (Python holds each
    undecodable byte as a surrogate escape, which plain UTF-8 cannot encode)."""
    relative = PurePath(os.path.relpath(os.path.abspath(path), os.path.abspath(root)))
    text = relative.as_posix()
    try:
        raw = text.encode("utf-8", "surrogateescape")
    except UnicodeEncodeError:  # a lone surrogate no byte stands for (a Windows name)
        raw = text.encode("utf-8", "surrogatepass")
    return hashlib.sha256(raw).hexdigest()


def assign(units: Sequence[Sequence[str]], count: int, root: Path) -> list[int]:
    """Deal ``units`` (groups of files that stay together) into ``count``
    shards: the shard index (0-based) of each unit. Units go largest first,
    each to the shard with the fewest files so far (the lowest index on a tie).
    The cost depends on the units only, never on ``count``: shards still empty
    are not held, since an empty shard is always the one with fewest files and
    the lowest empty index is the next never used."""
    keyed = sorted(
        range(len(units)),
        key=lambda i: (-len(units[i]), min(shard_key(p, root) for p in units[i])),
    )
    shard_of = [0] * len(units)
    used: list[tuple[int, int]] = []  # (files so far, shard index) of the shards in use
    for index in keyed:
        size = len(units[index])
        if len(used) < count:
            target, held = len(used), 0
        else:
            held, target = heapq.heappop(used)
        shard_of[index] = target
        heapq.heappush(used, (held + size, target))
    return shard_of


def partition(units: Sequence[Sequence[str]], count: int, root: Path, k: int) -> list[int]:
    """The indexes of the units that shard ``k`` (1-based) of ``count`` holds,
    in input order."""
    return [i for i, shard in enumerate(assign(units, count, root)) if shard == k - 1]


def select_shard(files: Sequence[str], shard: tuple[int, int], root: Path) -> list[str]:
    """The files of shard ``K`` of ``N`` (each file is its own unit)."""
    k, n = shard
    chosen = partition([[f] for f in files], n, root, k)
    return [files[i] for i in chosen]


def select_plan_shard(plan: ContextPlan, shard: tuple[int, int], root: Path) -> ContextPlan:
    """The part of a roots plan that shard ``K`` of ``N`` lints: whole groups
    of roots that share a changed file, and changed files linted alone."""
    from dataclasses import replace

    k, n = shard
    kept_roots, kept_alone = _shard_members(plan, k, n, root)
    return replace(
        plan,
        roots={r: changed for r, changed in plan.roots.items() if r in kept_roots},
        alone=tuple(p for p in plan.alone if p in kept_alone),
        # Roots whose layers could not be found are reported once, by the first shard.
        failed=plan.failed if k == 1 else (),
    )


def _shard_members(plan: ContextPlan, k: int, n: int, root: Path) -> tuple[set[str], set[str]]:
    """The roots and the lone files shard ``K`` of ``N`` lints: the roots that
    share a changed file are one unit, each lone file another."""
    roots = list(plan.roots)
    groups = _groups(roots, [plan.roots[r] for r in roots])
    units: list[list[str]] = [[roots[i] for i in group] for group in groups]
    units += [[path] for path in plan.alone]
    chosen = set(partition(units, n, root, k))
    kept_roots = {r for i in chosen if i < len(groups) for r in units[i]}
    kept_alone = {units[i][0] for i in chosen if i >= len(groups)}
    return kept_roots, kept_alone


def _groups(roots: Sequence[str], changed: Sequence[frozenset[str]]) -> list[list[int]]:
    """Indexes of roots joined (transitively) by a changed file they share."""
    parent = list(range(len(roots)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    owner: dict[str, int] = {}
    for index, keys in enumerate(changed):
        for key in keys:
            if key in owner:
                parent[find(index)] = find(owner[key])
            else:
                owner[key] = index
    groups: dict[int, list[int]] = {}
    for index in range(len(roots)):
        groups.setdefault(find(index), []).append(index)
    return list(groups.values())


__all__ = ["ShardError", "assign", "parse_shard", "partition", "select_plan_shard", "select_shard"]
