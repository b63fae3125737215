"""Changed layers linted in context.

A shot is many layers: the lighting layer authors the RenderSettings whose
camera lives in the layout layer. Linted alone, the lighting layer reports that
camera as missing. With config ``roots`` (globs of stage root files), each
changed file is linted inside every root that uses it, and only the findings
authored in the changed files are kept (a finding's ``layer``). A changed file
no root uses is linted on its own, with all its findings.
"""

from __future__ import annotations

import glob
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import field, replace

from pxr import Ar, Sdf, Tf, UsdUtils

from ..config import Settings
from ..engine import STAGE_OPEN_FAILED_CODE, register_plugins
from ..engine.stage import arcs_problem, file_problem
from ..layers.files import unreadable_reason
from ..model import INTERNAL_ERROR_CODE, FileResult, Finding, Report
from ..paths import display_path, is_utf8, usd_path
from ..records import record
from .workers import Pool, file_error

#: Tool problems are never filtered away: a root that cannot be opened or a rule
#: that raised means the changed files were not checked.
_ALWAYS_KEPT = frozenset({STAGE_OPEN_FAILED_CODE, INTERNAL_ERROR_CODE})


def file_key(path: str) -> str:
    """A comparable identity for a layer or file path: the real path of the
    file on disk (the outermost package for a layer inside a ``.usdz``)."""
    if is_utf8(path) and Ar.IsPackageRelativePath(path):
        # (Ar cannot take a name that is not UTF-8, nor give its parts back.)
        path = Ar.SplitPackageRelativePathOuter(path)[0]
    return os.path.normcase(os.path.realpath(path))


def find_roots(patterns: Sequence[str], base_dir: str) -> list[str]:
    """The files matching the ``roots`` globs (``**`` recurses), relative to
    ``base_dir`` (the config file's folder), sorted and without duplicates.
    They are named relative to the working directory when below it, as a user
    would have typed them."""
    return _roots(patterns, base_dir)[0]


def _roots(patterns: Sequence[str], base_dir: str) -> tuple[list[str], list[str]]:
    """:func:`find_roots`' files, and the patterns that match none."""
    found: dict[str, str] = {}
    unmatched = []
    for pattern in patterns:
        matched = False
        for match in glob.glob(pattern, root_dir=base_dir, recursive=True):
            path = os.path.join(base_dir, match)
            if os.path.isfile(path):
                matched = True
                found.setdefault(file_key(path), display_path(path))
        if not matched:
            unmatched.append(pattern)
    return sorted(found.values()), unmatched


def dependencies(root: str, missing: bool = False) -> frozenset[str]:
    """Keys of every file ``root`` depends on, itself included: its layer stack,
    references, payloads (in every variant), clips and other assets. With
    ``missing``, also where those that do not resolve would be (a path USD left
    relative, from ``root``'s folder): a sublayer saved later changes the stage."""
    register_plugins()  # before USD's first call here: engine/plugins.py
    with Tf.DiagnosticTrap() as trap:
        # The layers the check reads stay open for USD's walk: read once.
        held: list[Sdf.Layer] = []
        try:
            if _refused(root, held):
                # A layer USD must not read (a named pipe, a corrupt crate), which
                # its walk would wait on or choke on: ours stops at such a file.
                paths = list(_walk_layers(root))
            else:
                layers, assets, unresolved = UsdUtils.ComputeAllDependencies(root)
                paths = [layer.realPath or layer.identifier for layer in layers] + list(assets)
                if missing:
                    folder = os.path.dirname(os.path.abspath(root))
                    paths += [os.path.join(folder, p) for p in unresolved if "://" not in p]
        except Tf.ErrorException:
            # One unreadable layer anywhere (even in an unselected variant) makes
            # ComputeAllDependencies give up, while the stage itself may open.
            paths = list(_walk_layers(root))
        finally:
            trap.Clear()
    return frozenset(file_key(p) for p in paths)


def _refused(root: str, held: list[Sdf.Layer]) -> bool:
    """Whether ``root`` reaches a layer the engine refuses to hand USD
    (stage.arcs_problem: a lint of it is ST001 too); ``held`` gets the layers read."""
    layer = Sdf.Layer.FindOrOpen(usd_path(root))  # raises what it cannot read
    if layer is None:
        return False
    held.append(layer)
    return arcs_problem(layer, usd_path(root), held=held) is not None


def _walk_layers(root: str) -> Iterable[str]:
    """Layer by layer, the sublayers, references and payloads reachable from
    ``root``; a layer that cannot be opened is still a dependency."""
    pending, seen = [root], set()
    while pending:
        path = pending.pop()
        if file_key(path) in seen:
            continue
        seen.add(file_key(path))
        yield path
        if file_problem(path) is not None:
            continue  # never handed to USD, as a lint's arcs are not
        try:
            layer = Sdf.Layer.FindOrOpen(path)
        except Tf.ErrorException:
            layer = None
        if layer is None:
            continue
        pending.extend(
            layer.ComputeAbsolutePath(asset) for asset in layer.GetCompositionAssetDependencies()
        )


def _readable(path: str) -> bool:
    if unreadable_reason(path) is not None:
        return False  # never hand USD a FIFO: reading it blocks forever
    register_plugins()
    with Tf.DiagnosticTrap() as trap:
        try:
            return Sdf.Layer.FindOrOpen(path) is not None
        except Tf.ErrorException:
            return False
        finally:
            trap.Clear()


@record(frozen=True)
class ContextPlan:
    """What to lint for a set of changed files, and how to narrow the result."""

    #: Root file -> keys of the changed files it uses (their findings are kept).
    roots: Mapping[str, frozenset[str]] = field(default_factory=dict)
    #: Changed files no root uses: linted on their own, every finding kept.
    alone: tuple[str, ...] = ()
    #: Roots whose layers could not be found in time, as error results.
    failed: tuple[FileResult, ...] = ()
    #: What the run says of the plan (a ``roots`` glob that matches no file).
    notes: tuple[str, ...] = ()

    @property
    def files(self) -> list[str]:
        return [*self.roots, *self.alone]

    def keeps(self, finding: Finding) -> bool:
        """Whether :meth:`narrow` keeps ``finding`` of a file's lint (by where it
        is authored): what is fixed is what is reported."""
        changed = self.roots.get(finding.location.file)
        return changed is None or _is_in(finding, changed)

    def narrow(self, report: Report) -> Report:
        """Keep, for each root, the findings authored in the changed files it
        uses; a finding several roots share is reported once (first root)."""
        seen: set[tuple] = set()
        results = []
        for result in report.files:
            changed = self.roots.get(result.file)
            if changed is None:
                results.append(result)
                continue
            kept = []
            for finding in result.findings:
                if not _is_in(finding, changed):
                    continue
                identity = _identity(finding)
                if identity not in seen:
                    seen.add(identity)
                    kept.append(finding)
            results.append(replace(result, findings=tuple(kept)))
        return replace(report, files=tuple(results))


def _is_in(finding: Finding, changed: frozenset[str]) -> bool:
    if finding.code in _ALWAYS_KEPT:
        return True
    layer = finding.location.layer
    return layer is not None and file_key(layer) in changed


def _identity(finding: Finding) -> tuple:
    loc = finding.location
    return (finding.code, finding.message, loc.path, loc.layer, loc.line)


def plan_in_context(
    changed: Sequence[str],
    roots: Sequence[str],
    *,
    timeout: float | None = None,
    jobs: int = 1,
) -> ContextPlan:
    """Match the changed files against the roots' dependencies. A changed file
    USD cannot read is linted on its own: a root skips an unreadable sublayer
    with a mere warning, which would hide the file's syntax error (ST001).

    With a ``timeout`` USD reads the layers in worker processes, each root and
    each changed file within it (a FIFO in a layer stack blocks USD forever):
    a root that runs past it is an error result, a changed file is linted on
    its own (and its own lint is bounded too)."""
    questions = [("readable", path) for path in changed] + [("uses", root) for root in roots]
    if timeout:
        pool = Pool(_nothing, jobs, timeout, handle=_answer, failed=_unanswered)
        answers = list(pool.run(questions))
    else:
        answers = [_answer(None, question) for question in questions]
    readable = answers[: len(changed)]
    wanted = {file_key(path): path for path, ok in zip(changed, readable, strict=True) if ok}
    used: set[str] = set()
    by_root: dict[str, frozenset[str]] = {}
    failed = []
    for root, uses in zip(roots, answers[len(changed) :], strict=True):
        if isinstance(uses, FileResult):
            failed.append(uses)
            continue
        hits = uses.intersection(wanted)
        if hits:
            by_root[root] = frozenset(hits)
            used.update(hits)
    alone = tuple(path for path in changed if file_key(path) not in used)
    return ContextPlan(by_root, alone, tuple(failed))


def _nothing() -> None:
    return None


def _answer(_: None, question: tuple[str, str]) -> bool | frozenset[str]:
    kind, path = question
    return _readable(path) if kind == "readable" else dependencies(path)


def _unanswered(question: tuple[str, str], why: str) -> bool | FileResult:
    kind, path = question
    if kind == "readable":
        return False
    return file_error(path, f"finding the layers it uses {why}")


def plan_from_settings(
    changed: Sequence[str], settings: Settings, *, timeout: float | None = None, jobs: int = 1
) -> ContextPlan | None:
    """The plan for the configured ``roots`` globs (relative to the folder of
    the config file that set them), or None when no roots are configured."""
    if not settings.roots:
        return None
    base_dir = str(settings.base_dir)
    roots, unmatched = _roots(settings.roots, base_dir)
    plan = plan_in_context(changed, roots, timeout=timeout, jobs=jobs)
    # A mistyped root (or a folder, "shots/") silently linted every changed
    # layer on its own, out of the stage that gives it its camera.
    notes = tuple(
        f"note: {settings.where_entry('roots', pattern)}: {pattern!r} matches no file "
        f"below {display_path(base_dir) or base_dir}: changed layers no root uses are linted "
        "on their own"
        for pattern in unmatched
    )
    return replace(plan, notes=notes) if notes else plan


__all__ = [
    "ContextPlan",
    "dependencies",
    "file_key",
    "find_roots",
    "plan_from_settings",
    "plan_in_context",
]
