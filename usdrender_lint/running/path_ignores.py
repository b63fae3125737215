"""``per-path-ignores``: rules silenced in files matching a glob, applied to
the finished report (the configuration's counterpart of customData suppressions)."""

from __future__ import annotations

import dataclasses
import fnmatch
import os
import posixpath
import re
from collections.abc import Mapping, Sequence
from pathlib import Path, PurePosixPath

from ..api import Rule
from ..model import Finding, Report
from ..registry import matches_any
from .globs import expand_braces

#: The codes the engine reports whatever the selection or the path: a file it
#: could not check must never pass a gate (ST001 stage-open-failed).
UNIGNORABLE = ("ST001",)


def matches_path(pattern: str, path: str, base_dir: Path) -> bool:
    """Glob match of a file against a pattern relative to ``base_dir``.

    ``**/`` also matches no folder; a pattern without ``/`` matches the file
    name in any folder (as in ruff's per-file-ignores); an absolute pattern, or
    one that climbs out of ``base_dir`` (``../assets/*.usda``), matches the
    files it names. ``base_dir`` is resolved (the config file's folder), so a
    file named through a linked folder matches by its resolved path too.
    ``{a,b}`` matches either; an initial ``!`` matches the files the rest does
    not (both as ruff's per-file-ignores read them:
    https://docs.astral.sh/ruff/settings/#lint_per-file-ignores).
    """
    if pattern.startswith("!"):
        return not matches_path(pattern[1:], path, base_dir)
    absolute = os.path.abspath(path)
    resolved = os.path.realpath(absolute)
    return any(
        _matches(each, Path(p), base_dir)
        for each in expand_braces(pattern)
        for p in dict.fromkeys((absolute, resolved))
    )


def matches_any_path(pattern: str, paths: Sequence[str], base_dir: Path) -> bool:
    """Whether ``pattern`` matches one of ``paths`` (a linted file and the layer
    of a finding's opinion); a negated one matches when its rest matches none."""
    if pattern.startswith("!"):
        return not any(matches_path(pattern[1:], path, base_dir) for path in paths)
    return any(matches_path(pattern, path, base_dir) for path in paths)


def _matches(pattern: str, absolute: Path, base_dir: Path) -> bool:
    try:
        relative = PurePosixPath(absolute.relative_to(base_dir).as_posix())
    except ValueError:
        relative = PurePosixPath(absolute.as_posix())
    candidates = {pattern, pattern.replace("**/", "")}
    if "/" not in pattern:
        return any(fnmatch.fnmatchcase(relative.name, p) for p in candidates)
    if any(fnmatch.fnmatchcase(str(relative), re.sub(r"^(\./)+", "", p)) for p in candidates):
        return True
    # The path a pattern names from base_dir: an absolute one or a '../' one
    # never matches the relative path above.
    base = base_dir.as_posix()
    return any(
        fnmatch.fnmatchcase(absolute.as_posix(), posixpath.normpath(posixpath.join(base, p)))
        for p in candidates
    )


def apply_path_ignores(
    report: Report,
    per_path_ignores: Mapping[str, Sequence[str]],
    base_dir: Path,
    rules: Sequence[type[Rule]],
) -> Report:
    """Drop the findings per-path-ignores silence (codes, prefixes or names of
    ``rules``). A pattern matches the linted file or the layer that holds the
    finding's opinion. Internal errors (no rule) and UNIGNORABLE codes are never
    ignored."""
    if not per_path_ignores:
        return report
    base_dir = Path(os.path.abspath(base_dir))
    by_code = {rule.code: rule for rule in rules}

    def ignored(finding: Finding) -> bool:
        loc = finding.location
        places = [p for p in (loc.file, loc.layer) if p]
        rule = by_code.get(finding.code)
        return (
            rule is not None
            and rule.code not in UNIGNORABLE
            and any(
                matches_any(rule, selectors)
                for pattern, selectors in per_path_ignores.items()
                if matches_any_path(pattern, places, base_dir)
            )
        )

    files = tuple(
        dataclasses.replace(result, findings=tuple(f for f in result.findings if not ignored(f)))
        for result in report.files
    )
    return dataclasses.replace(report, files=files)
