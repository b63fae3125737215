"""Baselines: accept today's findings, fail only on new ones.

A fingerprint is the linted file relative to the baseline file's folder, the
rule code, the prim or property path and, for a finding --variants saw only
under other variant selections, those selections (so that the finding of the
authored selections stays known when --variants is added, and the one of
another selection is new); never a line number or a message
(values in messages change when the data does), so it survives edits that
move lines or reformat a layer. A count per fingerprint makes a second
identical finding new.
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections import Counter
from pathlib import Path, PurePath
from typing import Any

from ..atomic import named_descriptor, write_output
from ..model import Finding, Report
from ..reading import read_named_input

BASELINE_SCHEMA = 1

Fingerprint = tuple[str, str, str, str]


class BaselineError(Exception):
    """The baseline file cannot be read or written; the message names it."""


def fingerprint(finding: Finding, base_dir: Path) -> Fingerprint:
    """(file relative to ``base_dir`` with ``/`` separators, code, path,
    variant selection or '').
    ``base_dir`` is resolved, so the file is too: a file named through a linked
    folder (``$PWD`` below a link) has the fingerprint ``.`` gives it."""
    return (
        _relative(finding.location.file, base_dir),
        finding.code,
        finding.location.path or "",
        finding.variant_selection,
    )


def _relative(file: str, base_dir: Path) -> str:
    return PurePath(os.path.relpath(os.path.realpath(file), os.path.abspath(base_dir))).as_posix()


def _counts(report: Report, base_dir: Path) -> Counter[Fingerprint]:
    return Counter(fingerprint(f, base_dir) for f in report.findings)


def write_baseline(report: Report, path: str | Path) -> int:
    """Record every finding of ``report`` in ``path`` (atomically); returns how many."""
    path = Path(path)
    # Relative to the folder of the file behind a link, as --baseline reads it;
    # to the working directory for a stream this process holds (/dev/stdout).
    if named_descriptor(path) is not None:
        counts = _counts(report, Path.cwd())
    else:
        counts = _counts(report, Path(os.path.realpath(path)).parent)
    entries = [
        {
            "file": file,
            "code": code,
            "path": prim_path,
            **({"variant_selection": selection} if selection else {}),
            "count": count,
        }
        for (file, code, prim_path, selection), count in sorted(counts.items())
    ]
    document = {"usdrender_lint_baseline": BASELINE_SCHEMA, "findings": entries}
    try:
        write_output(path, json.dumps(document, indent=2) + "\n")
    except OSError as exc:
        raise BaselineError(f"{path}: cannot write baseline: {exc.strerror or exc}") from None
    return sum(counts.values())


def load_baseline(path: str | Path) -> Counter[Fingerprint]:
    """The fingerprint counts a baseline file records."""
    path = Path(path)
    document = _read_baseline(path)
    if not isinstance(document, dict) or "usdrender_lint_baseline" not in document:
        raise BaselineError(f"{path}: not a usdrender-lint baseline file")
    version = document["usdrender_lint_baseline"]
    # true and 1.0 equal 1 in Python, but no version of the tool writes them.
    if type(version) is not int or version != BASELINE_SCHEMA:
        raise BaselineError(
            f"{path}: unsupported baseline version {document['usdrender_lint_baseline']!r} "
            f"(expected {BASELINE_SCHEMA})"
        )
    entries = document.get("findings")
    if not isinstance(entries, list):
        raise BaselineError(f"{path}: 'findings' must be a list")
    counts: Counter[Fingerprint] = Counter()
    for index, entry in enumerate(entries):
        key, count = _entry(path, index, entry)
        counts[key] += count
    return counts


def _read_baseline(path: Path) -> Any:
    """The baseline file's JSON document; BaselineError when it cannot be read."""
    try:
        return json.loads(read_named_input(path).decode("utf-8"))
    except FileNotFoundError:
        raise BaselineError(
            f"{path}: baseline file not found (create it with --write-baseline)"
        ) from None
    except OSError as exc:
        raise BaselineError(f"{path}: cannot read baseline: {exc.strerror or exc}") from None
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise BaselineError(f"{path}: not a baseline file (invalid JSON: {exc})") from None
    except RecursionError:
        raise BaselineError(f"{path}: not a baseline file (JSON nested too deeply)") from None


def _entry(path: Path, index: int, entry: Any) -> tuple[Fingerprint, int]:
    """One recorded fingerprint and its count; BaselineError when malformed."""
    if not isinstance(entry, dict):
        raise BaselineError(f"{path}: findings[{index}] is malformed: {entry!r}")
    try:
        # (no variant_selection: a finding of the authored selections)
        key = (entry["file"], entry["code"], entry["path"], entry.get("variant_selection", ""))
        count = entry["count"]
    except KeyError as exc:
        raise BaselineError(f"{path}: findings[{index}] lacks {exc}") from None
    valid = all(isinstance(part, str) for part in key)
    if not valid or not isinstance(count, int) or isinstance(count, bool) or count < 1:
        raise BaselineError(f"{path}: findings[{index}] is malformed: {entry!r}")
    return key, count


def new_findings(report: Report, known: Counter[Fingerprint], base_dir: Path) -> tuple[Report, int]:
    """``report`` without the findings ``known`` (a loaded baseline whose file
    is in ``base_dir``) records, and how many were dropped. Of several findings
    with one fingerprint, the first ``count`` (in report order) are known and
    the rest are new."""
    remaining = Counter(known)
    dropped = 0

    def is_new(finding: Finding) -> bool:
        nonlocal dropped
        key = fingerprint(finding, base_dir)
        if remaining[key] > 0:
            remaining[key] -= 1
            dropped += 1
            return False
        return True

    files = tuple(
        dataclasses.replace(result, findings=tuple(f for f in result.findings if is_new(f)))
        for result in report.files
    )
    return dataclasses.replace(report, files=files), dropped


def stale_count(
    report: Report,
    known: Counter[Fingerprint],
    base_dir: Path,
    codes: frozenset[str],
    variants: bool,
) -> int:
    """How many findings ``known`` records that ``report`` (before the baseline
    hid any) no longer has: of the files it linted, by the rules that ran
    (``codes``), under other variant selections only when ``variants`` looked.
    A baseline that keeps them would hide them again when they come back."""
    found = _counts(report, base_dir)
    linted = {_relative(result.file, base_dir) for result in report.files}
    return sum(
        count - found[key]
        for key, count in known.items()
        if count > found[key] and key[0] in linted and key[1] in codes and (variants or not key[3])
    )
