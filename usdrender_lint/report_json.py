"""The report's JSON codec (``schema_version`` 1): :mod:`~usdrender_lint.model`
values to the documented JSON records and back. The JSON formatter writes
with it; ``merge``, baselines and the result cache read with it."""

from __future__ import annotations

import json
import os
import re
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, Literal

from .model import AppliedFix, FileResult, Finding, FixInfo, Location, Report, Severity
from .paths import display_path, escape
from .reading import read_named_input

SCHEMA_VERSION = 1
FILE_STATUSES = ("linted", "error")


class ReportFormatError(ValueError):
    """A document that is not a usdrender-lint JSON report of a known schema."""


def finding_to_dict(
    finding: Finding,
    layer_path: Callable[[str], str] = display_path,
    fix: FixInfo | None | Literal[False] = False,
) -> dict[str, Any]:
    """The finding as the report writes it; ``layer_path`` shows the layer
    (relative to the working directory by default); ``fix``: the fix to write
    when it is not the finding's own (Report.offered_fix)."""
    loc = finding.location
    if fix is False:
        fix = finding.fix
    return {
        "code": finding.code,
        "name": finding.name,
        "severity": finding.severity.value,
        "message": finding.message,
        "path": loc.path,
        "file": loc.file,
        "layer": layer_path(loc.layer) if loc.layer else None,
        "line": loc.line,
        "column": loc.column,
        "fix": None if fix is None else {"description": fix.description, "safe": fix.safe},
        # The renderer profile the finding was judged under, and why (R2-5).
        "profile": finding.profile,
        "profile_reason": finding.profile_reason,
    }


def fix_to_dict(fix: AppliedFix) -> dict[str, Any]:
    return {
        "file": fix.file,
        "code": fix.code,
        "path": fix.path,
        "layer": display_path(fix.layer) if fix.layer else None,
        "description": fix.description,
        "applied": fix.applied,
        "reason": fix.reason,
    }


#: A finding's fix the baseline holds back (Report.baseline_held): only on such a
#: finding, whose ``fix`` is null since --fix leaves it; merge reads it back.
HELD_FIX = "held_fix"


def _finding_in(report: Report, finding: Finding, file: str) -> dict[str, Any]:
    """The finding with the fix the run offers: none the baseline holds back,
    which is written apart (HELD_FIX)."""
    document = finding_to_dict(finding, fix=report.offered_fix(finding, file))
    held = finding.fix
    if held is not None and document["fix"] is None and finding in report.baseline_held:
        document[HELD_FIX] = {"description": held.description, "safe": held.safe}
    return document


def report_to_dict(
    report: Report,
    tool_name: str,
    tool_version: str,
    with_fixes: bool = False,
    statistics: list[dict[str, object]] | None = None,
    configuration: str | None = None,
    shard: tuple[int, int] | None = None,
) -> dict[str, Any]:
    """The report's document; ``statistics`` (--statistics) and ``fixes`` only
    when asked for or fixes were made, so the default document stays as documented.
    ``shard``: the ``(K, N)`` of ``check --shard K/N``, which merge checks."""
    document: dict[str, Any] = {
        "schema_version": SCHEMA_VERSION,
        "tool": {"name": tool_name, "version": tool_version},
        # What merge compares (running/merge.py); written by check and merge.
        **({"configuration": configuration} if configuration else {}),
        **({"shard": {"index": shard[0], "count": shard[1]}} if shard else {}),
        # What the shard's relative paths (config_file) are relative to, for a
        # merge run from another folder.
        **({"working_directory": cwd} if shard and (cwd := _working_directory()) else {}),
        "files": [
            {
                "file": result.file,
                "status": result.status,
                "error": result.error,
                "findings": [_finding_in(report, f, result.file) for f in result.findings],
                # Which configuration judged it (a tree of shows has several).
                "config_file": display_path(result.config) if result.config else None,
                # Lines for the user beside its findings (--variants' skipped
                # combinations): what merge prints again, as check did.
                **({"notes": list(result.notes)} if result.notes else {}),
            }
            for result in report.files
        ],
        "summary": {
            "files": len(report.files),
            "findings": len(report.findings),
            "by_severity": report.by_severity(),
        },
    }
    if statistics is not None:
        document["statistics"] = statistics
    if with_fixes or report.applied_fixes or report.unapplied_fixes:
        document["fixes"] = [
            fix_to_dict(fix) for fix in (*report.applied_fixes, *report.unapplied_fixes)
        ]
    return document


def _field(data: Mapping[str, Any], key: str, kind: type | tuple[type, ...], where: str) -> Any:
    value = data.get(key) if isinstance(data, Mapping) else None
    if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
        raise ReportFormatError(f"{where}: '{key}' is missing or not a {_kind_name(kind)}")
    return value


def _kind_name(kind: type | tuple[type, ...]) -> str:
    kinds = kind if isinstance(kind, tuple) else (kind,)
    return " or ".join("null" if k is type(None) else k.__name__ for k in kinds)


_OPTIONAL_STR = (str, type(None))


def finding_from_dict(data: Mapping[str, Any], where: str = "finding") -> Finding:
    """The :class:`Finding` a :func:`finding_to_dict` record describes."""
    name = _field(data, "severity", str, where)  # its error names the place already
    try:
        severity = Severity.parse(name)
    except ValueError as exc:
        raise ReportFormatError(f"{where}: {exc}") from None
    fix = _fix_info(data, "fix", where)
    if fix is None:  # a fix the baseline held back is the finding's still (report_from_dict)
        fix = _fix_info(data, HELD_FIX, where)
    line, column = data.get("line"), data.get("column")  # "column" came later: optional
    for key, number in (("line", line), ("column", column)):
        if number is not None and (not isinstance(number, int) or isinstance(number, bool)):
            raise ReportFormatError(f"{where}: '{key}' is not an integer")
    location = Location(
        _field(data, "file", str, where),
        _field(data, "path", _OPTIONAL_STR, where),
        _field(data, "layer", _OPTIONAL_STR, where),
        line,
        column,
    )
    profile, reason = data.get("profile"), data.get("profile_reason")
    if not isinstance(profile, _OPTIONAL_STR) or not isinstance(reason, _OPTIONAL_STR):
        raise ReportFormatError(f"{where}: 'profile' and 'profile_reason' are strings or null")
    return Finding(
        _field(data, "code", str, where),
        _field(data, "name", str, where),
        severity,
        _field(data, "message", str, where),
        location,
        fix,
        profile,
        reason,
    )


def _fix_info(data: Mapping[str, Any], key: str, where: str) -> FixInfo | None:
    fix = data.get(key)
    if fix is None:
        return None
    return FixInfo(
        _field(fix, "description", str, f"{where}.{key}"), _field(fix, "safe", bool, where)
    )


def result_from_dict(data: Mapping[str, Any], where: str = "file") -> FileResult:
    """The :class:`FileResult` of one entry of a report's ``files``."""
    status = _field(data, "status", str, where)
    if status not in FILE_STATUSES:
        raise ReportFormatError(f"{where}: unknown status {status!r}")
    findings = _field(data, "findings", list, where)
    notes = data.get("notes", [])
    if not isinstance(notes, list) or not all(isinstance(n, str) for n in notes):
        raise ReportFormatError(f"{where}: 'notes' is not a list of strings")
    return FileResult(
        _field(data, "file", str, where),
        status,
        _field(data, "error", _OPTIONAL_STR, where),
        tuple(finding_from_dict(f, f"{where}.findings[{i}]") for i, f in enumerate(findings)),
        tuple(notes),
        config=_optional(data, "config_file", where),
    )


def _optional(data: Mapping[str, Any], key: str, where: str) -> str | None:
    """A string or null that a report may lack (a field added later)."""
    value = data.get(key)
    if not isinstance(value, _OPTIONAL_STR):
        raise ReportFormatError(f"{where}: '{key}' is not a string or null")
    return value


def _working_directory() -> str | None:
    try:
        return os.getcwd()
    except OSError:  # gone, or too long to name: the paths written are absolute
        return None


def working_directory_from_dict(document: Mapping[str, Any]) -> str | None:
    """The working directory a shard's report records (its relative paths are
    relative to it); None when it records none, or one this system cannot
    name (another system's: merge reads the paths from its own folder)."""
    value = document.get("working_directory")
    if value is not None and not isinstance(value, str):
        raise ReportFormatError("'working_directory' is not a string")
    return value if value and os.path.isabs(value) else None


def shard_from_dict(document: Mapping[str, Any]) -> tuple[int, int] | None:
    """The ``(K, N)`` a report of ``check --shard K/N`` records; None for a
    report of a whole run."""
    shard = document.get("shard")
    if shard is None:
        return None
    if isinstance(shard, Mapping):
        index, count = shard.get("index"), shard.get("count")
        if (
            isinstance(index, int)
            and isinstance(count, int)
            and not isinstance(index, bool)
            and not isinstance(count, bool)
            and 1 <= index <= count
        ):
            return index, count
    raise ReportFormatError("'shard' is not {index: K, count: N} with 1 <= K <= N")


def _fix_from_dict(data: Mapping[str, Any], where: str) -> AppliedFix:
    applied = _field(data, "applied", bool, where)
    reason = _field(data, "reason", _OPTIONAL_STR, where)
    if applied != (reason is None):
        raise ReportFormatError(f"{where}: 'applied' and 'reason' disagree")
    return AppliedFix(
        _field(data, "file", str, where),
        _field(data, "code", str, where),
        _field(data, "path", _OPTIONAL_STR, where),
        _field(data, "layer", _OPTIONAL_STR, where),
        _field(data, "description", str, where),
        reason,
    )


def report_from_dict(document: Any) -> Report:
    """The :class:`Report` a ``--format json`` document describes (its rules,
    statistics and summary are derived data and not read back). Names that
    are not UTF-8, which the document holds escaped (:func:`restored`), are
    read back as Python names them, so a report read back renders as the
    report that was written."""
    if not isinstance(document, Mapping):
        raise ReportFormatError("not a JSON object")
    document = _restored_strings(document)
    version = document.get("schema_version")
    if version != SCHEMA_VERSION:
        raise ReportFormatError(
            f"schema_version {version!r} is not {SCHEMA_VERSION}: not a usdrender-lint "
            "JSON report, or one from an incompatible version"
        )
    files = _field(document, "files", list, "report")
    if any(isinstance(f, Mapping) and f.get("status") == "computed" for f in files):
        raise ReportFormatError("a document of 'usdrender-lint spec', not a check report")
    fixes = [_fix_from_dict(f, f"fixes[{i}]") for i, f in enumerate(document.get("fixes") or ())]
    results = tuple(result_from_dict(f, f"files[{i}]") for i, f in enumerate(files))
    held = frozenset(
        finding
        for result, entry in zip(results, files, strict=True)
        for finding, data in zip(result.findings, entry["findings"], strict=True)
        if isinstance(data, Mapping) and data.get("fix") is None and data.get(HELD_FIX)
    )
    return Report(
        results,
        applied_fixes=tuple(f for f in fixes if f.applied),
        unapplied_fixes=tuple(f for f in fixes if not f.applied),
        baseline_held=held,
    )


#: The escapes :func:`~usdrender_lint.paths.escape` writes: a doubled backslash
#: and ``\\xNN`` for a byte that is not UTF-8; any other backslash is no escape.
_ESCAPES = re.compile(r"\\(?:(\\)|x([0-9a-f]{2}))?")


def restored(text: str) -> str:
    """The name a JSON report's string stands for: the inverse of
    :func:`~usdrender_lint.paths.escape`, which writes a name that is not
    UTF-8 in an escaped form. A string is read as escaped only when escaping
    what it stands for gives it back, so the reading follows ``escape`` and a
    name that is UTF-8 and was written as it is stays as it is. While
    ``escape`` leaves a UTF-8 name as it is, one case stays ambiguous: a UTF-8
    name that spells an escape (``a\\xff``: a backslash, then ``xff``) is read
    as the name that is not UTF-8."""
    if "\\" not in text:
        return text
    raw = bytearray()
    end = 0
    try:
        for match in _ESCAPES.finditer(text):
            raw += text[end : match.start()].encode("utf-8")
            if match.group(1):
                raw += b"\\"
            elif match.group(2):
                raw.append(int(match.group(2), 16))
            else:
                return text
            end = match.end()
        raw += text[end:].encode("utf-8")
    except UnicodeEncodeError:  # a lone surrogate: not a text escape() wrote
        return text
    name = bytes(raw).decode("utf-8", "surrogateescape")
    return name if name != text and escape(name) == text else text


def _restored_strings(value: Any) -> Any:
    """``value`` (a JSON document) with every string, keys included, :func:`restored`."""
    if isinstance(value, str):
        return restored(value)
    if isinstance(value, dict):
        return {_restored_strings(k): _restored_strings(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_restored_strings(item) for item in value]
    return value


def read_document(path: str | Path) -> Any:
    """A JSON file's document; raises :class:`ReportFormatError` naming it
    (a document nested too deeply for the parser included)."""
    try:
        text = read_named_input(path).decode("utf-8")
    except OSError as exc:
        raise ReportFormatError(f"{path}: cannot read: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise ReportFormatError(f"{path}: not UTF-8 text") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise ReportFormatError(f"{path}: not JSON: {exc}") from None
    except RecursionError:
        raise ReportFormatError(f"{path}: not a report: JSON nested too deeply") from None


def read_report(path: str | Path) -> Report:
    """Read a JSON report file; raises :class:`ReportFormatError` naming it."""
    document = read_document(path)
    try:
        return report_from_dict(document)
    except ReportFormatError as exc:
        raise ReportFormatError(f"{path}: {exc}") from None
