"""``usdrender-lint merge REPORT...``: the JSON reports of ``check --shard K/N``
jobs (or any JSON reports) as one report, in any format.

Reports merge only when they could be parts of one run: the same tool version
and the same configuration (the ``configuration`` digest a check writes into
its JSON report: the rules that ran and their options and severities, the
settings, the usd-core version and the baseline). A file that several reports
hold is kept once when they agree about it (same status, error and findings);
when they disagree, the merge is refused, naming the file and the two reports,
since no rule can tell which one is right. The files are ordered by path, so
the merged report does not depend on which shard linted what or on the order
the reports are given in; fixes are kept in report order.

The reports of ``check --shard K/N`` record K and N, and must be the whole
run: exactly the shards 1 to N of one N. A missing shard (a job that failed
or was cancelled), shards of different counts, or two reports of one shard
that differ are refused, since the merge would otherwise gate on part of the
files. A shard given twice with the same content is read once. Reports of
whole runs (no ``--shard``) merge as they are, with each other and with a
complete set of shards; a fix that several reports hold is kept once.
"""

from __future__ import annotations

import hashlib
import json
import re
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from ..model import AppliedFix, FileResult, Finding, Report
from ..report_json import (
    ReportFormatError,
    read_document,
    report_from_dict,
    shard_from_dict,
    working_directory_from_dict,
)

if TYPE_CHECKING:
    from collections import Counter

    from ..api import Rule
    from ..config import Settings


class MergeError(Exception):
    """Reports that cannot be read or merged; the message names the files."""


def configuration_digest(
    settings: Settings, rules: Sequence[Rule], baseline: Counter | None = None
) -> str:
    """What decides a run's findings besides the files, the same on every
    machine and checkout (no paths, times or environment): two reports with
    the same digest come from runs that judge a file alike."""
    from pxr import Usd

    from ..settings_table import settings_key

    parts = {
        "usd": list(Usd.GetVersion()),
        "rules": [
            (type(rule).__module__, type(rule).__qualname__, rule.code, _portable(rule.options))
            for rule in rules
        ],
        "settings": settings_key(settings),
        "baseline": sorted(baseline.items()) if baseline else None,
    }
    text = json.dumps(parts, sort_keys=True, default=repr, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:32]


def digest_of_parts(digests: Sequence[str]) -> str:
    """The digest of a run split by configuration (running/hierarchy.py): its
    parts', as a set. Every shard of a split run has every part (some with
    no file), so the shards of one run agree."""
    text = ",".join(sorted(set(digests)))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:32]


def _portable(value: object) -> str:
    """``repr(value)`` without object addresses (a plugin's options class
    without its own repr), which differ between the machines of one CI run."""
    return re.sub(r" at 0x[0-9a-fA-F]+", "", repr(value))


def merge_reports(paths: Sequence[str]) -> tuple[Report, str | None, dict[str, str]]:
    """One report holding every file of the reports at ``paths``, the
    configuration digest they share (None for reports written without one),
    and the working directory each file's report records (a shard's: its
    relative paths are relative to it), by file."""
    if not paths:
        raise MergeError("merge needs at least one JSON report")
    files: dict[str, tuple[FileResult, str]] = {}
    where: dict[str, str] = {}
    held_back: set[Finding] = set()
    applied: list[AppliedFix] = []
    unapplied: list[AppliedFix] = []
    first: tuple[str, str | None, str | None] | None = None
    shards: dict[tuple[int, int], tuple[str, Report]] = {}
    for path in paths:
        try:
            document = read_document(path)
        except ReportFormatError as exc:
            raise MergeError(str(exc)) from None
        try:
            report = report_from_dict(document)
            shard = shard_from_dict(document)
            working_directory = working_directory_from_dict(document)
        except ReportFormatError as exc:
            raise MergeError(f"{path}: {exc}") from None
        held_back.update(report.baseline_held)
        identity = (path, _version(document), _configuration(document))
        if first is None:
            first = identity
        _same_run(first, identity)
        for result in report.files:
            if working_directory is not None:
                where.setdefault(result.file, working_directory)
            held = files.setdefault(result.file, (result, path))
            if held[0] != result:
                raise MergeError(
                    f"{held[1]} and {path} disagree about {result.file} "
                    f"({_summary(held[0])} vs {_summary(result)}): not parts of one run"
                )
        if shard is not None:
            twin = shards.setdefault(shard, (path, report))
            if twin[1] != report:
                raise MergeError(
                    f"{twin[0]} and {path} are both shard {shard[0]}/{shard[1]} but hold "
                    "different files or fixes: not parts of one run"
                )
            if twin[0] != path:
                continue  # the same shard again: its files are held, its fixes too
        # A fix an earlier report holds is that report's too (the same report
        # given twice, a whole run beside its shards): once, as its file is.
        earlier = set(applied), set(unapplied)
        applied.extend(fix for fix in report.applied_fixes if fix not in earlier[0])
        unapplied.extend(fix for fix in report.unapplied_fixes if fix not in earlier[1])
    _whole_run({shard: path for shard, (path, _report) in shards.items()})
    merged = Report(
        tuple(files[name][0] for name in sorted(files)),
        applied_fixes=tuple(applied),
        unapplied_fixes=tuple(unapplied),
        baseline_held=frozenset(held_back),
    )
    assert first is not None
    return merged, first[2], where


def _version(document: Mapping[str, Any]) -> str | None:
    tool = document.get("tool")
    version = tool.get("version") if isinstance(tool, Mapping) else None
    return version if isinstance(version, str) else None


def _configuration(document: Mapping[str, Any]) -> str | None:
    value = document.get("configuration")
    return value if isinstance(value, str) else None


def _same_run(
    first: tuple[str, str | None, str | None], other: tuple[str, str | None, str | None]
) -> None:
    if other[1] != first[1]:
        raise MergeError(
            f"{first[0]} and {other[0]} were made by different versions "
            f"({first[1]} and {other[1]}): lint every part with one version"
        )
    if other[2] != first[2]:
        raise MergeError(
            f"{first[0]} and {other[0]} were made with different configurations "
            "(rules, options, settings or baseline): lint every part with the same ones"
        )


def _whole_run(shards: Mapping[tuple[int, int], str]) -> None:
    """Refuse shards that are not exactly 1/N to N/N of one N (the report of
    each shard given: its path)."""
    if not shards:
        return
    counts = sorted({count for _index, count in shards})
    if len(counts) > 1:
        one, other = (
            min((shard, path) for shard, path in shards.items() if shard[1] == count)
            for count in counts[:2]
        )
        raise MergeError(
            f"{one[1]} is shard {one[0][0]}/{one[0][1]} and {other[1]} is shard "
            f"{other[0][0]}/{other[0][1]}: the shards of one run have one N; "
            "lint every part with the same --shard count"
        )
    count = counts[0]
    absent = count - len(shards)
    if absent:
        named: list[str] = []
        index = 1
        while len(named) < 3 and index <= count:  # the first few (N may be huge)
            if (index, count) not in shards:
                named.append(f"{index}/{count}")
            index += 1
        more = ", ..." if absent > len(named) else ""
        raise MergeError(
            f"{absent:,} of {count:,} shard{'s' if count != 1 else ''} missing "
            f"({', '.join(named)}{more}): merge needs the report of every shard "
            f"1/{count} to {count}/{count}, or it would gate on part of the files"
        )


def _summary(result: FileResult) -> str:
    if result.status != "linted":
        return result.status
    return f"{len(result.findings)} finding{'s' if len(result.findings) != 1 else ''}"


__all__ = ["MergeError", "configuration_digest", "merge_reports"]
