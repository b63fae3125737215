"""The rule engine: open a stage, walk it once, run the rules, make findings.

It knows rules (through :mod:`.api`) and the data model, never a formatter or
the command line.
"""

from __future__ import annotations

import os
import traceback
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from pxr import Sdf, Tf, Usd, UsdRender

from . import fastpath, resolve, suppress, usda_lines
from .api import Context, Diagnostic, Fix, FullStageRequired, Rule
from .model import (
    INTERNAL_ERROR_CODE,
    INTERNAL_ERROR_NAME,
    FileResult,
    Finding,
    FixInfo,
    Location,
    Severity,
)

STAGE_OPEN_FAILED_CODE = "ST001"
STAGE_OPEN_FAILED_NAME = "stage-open-failed"
#: Longest finding message kept (see bounded_message).
MAX_MESSAGE_CHARS = 2000
USD_EXTENSIONS = (".usd", ".usda", ".usdc", ".usdz")
#: Set to 1 to compose every stage in full (no fast path; see fastpath.py).
FULL_COMPOSITION_ENV = "USDRENDER_LINT_FULL_COMPOSITION"

#: The render prim kinds the engine collects during its walk (Context.render_prims).
RENDER_SCHEMAS: tuple[type, ...] = (
    UsdRender.Settings,
    UsdRender.Product,
    UsdRender.Var,
    UsdRender.Pass,
)


class CorruptValue(Exception):
    """USD found a corrupt value in a layer while a rule read it (the file's
    problem, reported as ST001)."""


@dataclass(frozen=True)
class StageOpenResult:
    stage: Usd.Stage | None
    #: One line per error USD posted when the stage could not be opened.
    errors: tuple[str, ...] = ()


def open_stage(path: str, session_layer: Sdf.Layer | None = None) -> StageOpenResult:
    """Open a stage with every payload loaded, keeping USD's diagnostics off stderr.
    ``session_layer`` (e.g. the fixer's --fix-to layer) replaces the anonymous one.

    usd-core turns every Tf error posted during ``Open`` into an exception and
    the stage handle is lost (catalog, ST001); its lines carry ``file:line:col``.
    """
    with Tf.DiagnosticTrap() as trap:
        try:
            if session_layer is None:
                stage = Usd.Stage.Open(path, Usd.Stage.LoadAll)
            else:
                root = Sdf.Layer.FindOrOpen(path)
                stage = Usd.Stage.Open(root, session_layer, Usd.Stage.LoadAll) if root else None
            errors: tuple[str, ...] = ()
        except Tf.ErrorException as exc:
            stage = None
            errors = tuple(_error_lines(exc, path))
        except Exception as exc:  # noqa: BLE001 - any failure to open is a finding
            stage = None
            errors = (f"{type(exc).__name__}: {exc}",)
        trap.Clear()
    if stage is None and path.lower().endswith(".usdz"):
        problem = _package_problem(path)
        errors = ((problem,) if problem else ()) + errors
    if stage is None and not errors:
        errors = (f"USD could not open {path}",)
    return StageOpenResult(stage, errors)


def _package_problem(path: str) -> str | None:
    """Why a ``.usdz`` is not a package USD reads; USD itself says only
    "Failed to open layer" for these."""
    import zipfile  # only for a .usdz USD could not open

    try:
        with zipfile.ZipFile(path) as archive:
            entries = archive.infolist()
    except (zipfile.BadZipFile, OSError, ValueError):
        return "not a zip archive (a .usdz is an uncompressed zip whose first file is a layer)"
    if not entries:
        return "the .usdz package is empty"
    first = entries[0].filename
    if not first.lower().endswith((".usd", ".usda", ".usdc")):
        return f"the first file in the .usdz package, {first!r}, is not a USD layer"
    return None


def _error_lines(exc: Tf.ErrorException, path: str) -> Iterable[str]:
    for arg in exc.args:
        try:
            text = getattr(arg, "commentary", None) or str(arg)
        except UnicodeDecodeError:
            # USD quotes the offending text, and Python cannot decode the quote.
            text = _undecodable_error(path)
        for line in str(text).strip().splitlines():
            if line.strip():
                yield line.strip()


def _undecodable_error(path: str) -> str:
    """Say where a layer stops being UTF-8 (usd-core 26.11's usda parser
    rejects invalid UTF-8 anywhere in the file, comments included)."""
    try:
        with open(path, "rb") as handle:
            data = handle.read()
        data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        return (
            f"{path}:{line}:{column}: invalid UTF-8 (byte 0x{data[exc.start]:02x}); "
            "USD's parser rejects the file"
        )
    except OSError:
        pass
    return "USD reported an error whose message is not valid UTF-8"


@dataclass(frozen=True)
class TracedFinding:
    """A finding with its Fix and origin: the code of the rule that produced it
    (an internal-error finding keeps the rule that raised) and the prim whose
    ``check_prim`` did (None for ``check_stage`` and the engine's own findings)."""

    finding: Finding
    fix: Fix | None
    rule_code: str
    prim_path: Sdf.Path | None


class _TypeDispatch:
    """Which rules want a prim, keyed by its type name (no per-prim ``IsA``)."""

    def __init__(self, rules: Sequence[Rule]) -> None:
        self._rules = rules
        self._by_type_name: dict[str, tuple[tuple[Rule, ...], tuple[type, ...]]] = {}
        self._wanted = {schema for rule in rules for schema in rule.prim_types}
        self._wanted.update(RENDER_SCHEMAS)
        self._tf_types = {schema: Tf.Type.Find(schema) for schema in self._wanted}
        #: Type names no registered schema defines (USD composes them typeless).
        self.unknown_type_names: set[str] = set()

    def lookup(self, type_name: str) -> tuple[tuple[Rule, ...], tuple[type, ...]]:
        """(rules to run, render schemas the type belongs to) for a type name."""
        entry = self._by_type_name.get(type_name)
        if entry is None:
            prim_type = Usd.SchemaRegistry.GetTypeFromName(type_name) if type_name else None
            if prim_type is not None and (
                prim_type.isUnknown or not Usd.SchemaRegistry.IsConcrete(prim_type)
            ):
                # USD gives a prim of an unknown or abstract type (`def RenderSettingsBase`)
                # no schema type: IsA is false for it, so no rule must treat it as typed.
                self.unknown_type_names.add(type_name)
                prim_type = None
            matches = {
                schema
                for schema, tf_type in self._tf_types.items()
                if prim_type is not None and not prim_type.isUnknown and prim_type.IsA(tf_type)
            }
            rules = tuple(r for r in self._rules if matches.intersection(r.prim_types))
            kinds = tuple(s for s in RENDER_SCHEMAS if s in matches)
            entry = self._by_type_name[type_name] = (rules, kinds)
        return entry

    def wants(self, type_name: str) -> bool:
        """True when prims of this type must be composed: a rule or the render
        prim lists want them, or no schema defines the type (unknown_type_prims)."""
        rules, kinds = self.lookup(type_name)
        return bool(rules or kinds) or type_name in self.unknown_type_names


class Linter:
    """Runs a fixed set of configured rules over files or stages.

    ``severities`` overrides rule default severities by code. With
    ``raise_errors`` a rule that raises propagates (for tests) instead of
    becoming an internal-error finding. ``lint_path`` composes only what the
    rules read when that provably gives the same findings (fastpath.py);
    ``full_composition`` (default: the USDRENDER_LINT_FULL_COMPOSITION
    environment variable) always composes the whole stage.
    """

    def __init__(
        self,
        rules: Sequence[Rule],
        severities: Mapping[str, Severity] | None = None,
        *,
        time_sample_cap: int = 1000,
        raise_errors: bool = False,
        known_rules: Sequence[type[Rule]] | None = None,
        full_composition: bool | None = None,
    ) -> None:
        self.rules = tuple(rules)
        if full_composition is None:
            full_composition = os.environ.get(FULL_COMPOSITION_ENV, "") not in ("", "0")
        self.full_composition = full_composition
        self.severities = dict(severities or {})
        self.time_sample_cap = time_sample_cap
        self.raise_errors = raise_errors
        #: Every registered rule, so a customData suppression naming a rule that
        #: was not selected is not reported as naming no rule (default: ``rules``).
        self.known_rules = known_rules
        self._dispatch = _TypeDispatch(self.rules)
        #: Rules with a check_stage of their own (most have none: no call per file).
        self._stage_rules = tuple(r for r in self.rules if _overrides(r, "check_stage"))
        #: While lint_stage_with_fixes runs: each finding's Fix (the callable
        #: Finding.fix drops, since findings stay free of pxr objects).
        self._fixes: dict[Finding, Fix] | None = None
        #: While lint_stage_traced runs: the rule code and check_prim prim behind each finding.
        self._origins: dict[Finding, tuple[str, Sdf.Path | None]] | None = None

    # -- entry points ---------------------------------------------------------

    def lint_path(self, path: str) -> FileResult:
        """Lint one file; never raises for a bad file."""
        problem = _unreadable_reason(path)
        if problem is not None:
            return FileResult(path, status="error", error=f"{path}: {problem}")
        try:
            return self._lint_file(path)
        except UnicodeDecodeError as exc:
            # A corrupt crate can hold names that are not UTF-8: USD composes
            # them, but every Python read of them raises.
            byte = exc.object[exc.start : exc.start + 1].hex()
            message = (
                f"the file holds a name or string that is not valid UTF-8 (byte 0x{byte}); "
                "USD reads it, but nothing in it can be checked: the file is probably corrupt"
            )
        except CorruptValue as exc:
            message = str(exc)
        location = Location(path, None, os.path.abspath(path), None)
        severity = self._severity(STAGE_OPEN_FAILED_CODE, Severity.ERROR)
        finding = Finding(
            STAGE_OPEN_FAILED_CODE, STAGE_OPEN_FAILED_NAME, severity, message, location
        )
        return FileResult(path, findings=(finding,))

    def _lint_file(self, path: str) -> FileResult:
        partial = None if self.full_composition else self._open_partial(path)
        if partial is not None and partial.stage is not None:
            try:
                findings = self._lint(partial.stage, path, partial=True)
                return FileResult(path, findings=tuple(findings))
            except FullStageRequired:
                pass  # a rule reads the whole scene: compose all of it below
            finally:
                usda_lines.clear_cache()
        opened = open_stage(path)
        if opened.stage is None:
            return FileResult(path, findings=tuple(self._open_failure_findings(path, opened)))
        try:
            findings = self.lint_stage(opened.stage, path)
        finally:
            usda_lines.clear_cache()
        return FileResult(path, findings=tuple(findings))

    def lint_stage(self, stage: Usd.Stage, file: str | None = None) -> list[Finding]:
        """Lint an open stage; ``file`` names it in findings (default: root layer)."""
        return self._lint(stage, file)

    def lint_stage_with_fixes(
        self, stage: Usd.Stage, file: str | None = None
    ) -> list[tuple[Finding, Fix | None]]:
        """Like :meth:`lint_stage`, each finding paired with the rule's Fix (for the fixer)."""
        self._fixes = {}
        try:
            findings = self._lint(stage, file)
            return [(finding, self._fixes.get(finding)) for finding in findings]
        finally:
            self._fixes = None

    def lint_stage_traced(self, stage: Usd.Stage, file: str | None = None) -> list[TracedFinding]:
        """Like :meth:`lint_stage_with_fixes`, each finding also naming the rule
        and the prim (for ``check_prim``) that produced it (UsdValidation adaptor)."""
        self._origins = {}
        try:
            return [
                TracedFinding(finding, fix, *self._origins.get(finding, (finding.code, None)))
                for finding, fix in self.lint_stage_with_fixes(stage, file)
            ]
        finally:
            self._origins = None

    def _open_partial(self, path: str) -> fastpath.PartialStage | None:
        try:
            return fastpath.open_partial(path, self._dispatch.wants)
        except Exception:  # noqa: BLE001 - an optimisation must never cost a file
            if self.raise_errors:
                raise
            return None

    def _lint(self, stage: Usd.Stage, file: str | None, partial: bool = False) -> list[Finding]:
        file = file or stage.GetRootLayer().realPath or stage.GetRootLayer().identifier
        ctx = Context(stage=stage, file=file, time_sample_cap=self.time_sample_cap, partial=partial)
        findings: list[Finding] = []
        # Nothing edits the stage while rules run, so resolve.py may memoise.
        with Tf.DiagnosticTrap() as trap, resolve.lint_memo():
            try:
                work, suppressing = self._walk(stage, ctx)
                run = self._run
                for rule in self._stage_rules:
                    findings.extend(run(rule, ctx, rule.check_stage, ctx))
                for prim, rules in work:
                    for rule in rules:
                        findings.extend(run(rule, ctx, rule.check_prim, prim, ctx))
                findings = self._apply_data_suppressions(ctx, findings, suppressing)
            finally:
                trap.Clear()
        return sorted(set(findings), key=Finding.sort_key)

    def _apply_data_suppressions(
        self, ctx: Context, findings: list[Finding], suppressing: list[Usd.Prim]
    ) -> list[Finding]:
        """Drop findings silenced in customData; report unused suppressions."""
        kept, unused = suppress.apply_data_suppressions(
            ctx.stage, findings, self.rules, self.known_rules, suppressing=suppressing
        )
        for rule in self.rules:
            if rule.code == suppress.UNUSED_SUPPRESSION_CODE:
                kept.extend(self._finding(rule, diagnostic, ctx) for diagnostic in unused)
        return kept

    # -- internals ------------------------------------------------------------

    def _walk(
        self, stage: Usd.Stage, ctx: Context
    ) -> tuple[list[tuple[Usd.Prim, tuple[Rule, ...]]], list[Usd.Prim]]:
        """One traversal of usable prims: collect render prims, the prim work and
        the prims with customData suppressions (no second traversal for those)."""
        work = []
        suppressing = []
        unknown = self._dispatch.unknown_type_names
        has_suppressions = suppress.has_suppressions
        for prim in stage.Traverse():
            if has_suppressions(prim):
                suppressing.append(prim)
            type_name = prim.GetTypeName()
            rules, kinds = self._dispatch.lookup(type_name)
            for kind in kinds:
                ctx.render_prims.setdefault(kind, []).append(prim)
            if rules:
                work.append((prim, rules))
            if type_name in unknown:
                ctx.unknown_type_prims.append(prim)
        return work, suppressing

    def _run(self, rule: Rule, ctx: Context, hook, *args) -> list[Finding]:
        try:
            findings = [self._finding(rule, diagnostic, ctx) for diagnostic in hook(*args) or ()]
        except (FullStageRequired, UnicodeDecodeError):
            raise  # a corrupt name is the file's problem, not the rule's (see lint_path)
        except Exception as exc:
            findings = [self._rule_error(rule, ctx, exc, args[0])]
        if self._origins is not None:
            prim = args[0].GetPath() if isinstance(args[0], Usd.Prim) else None
            for finding in findings:
                self._origins.setdefault(finding, (rule.code, prim))
        return findings

    def _rule_error(self, rule: Rule, ctx: Context, exc: Exception, target: object) -> Finding:
        """The internal-error finding for a hook that raised on ``target``
        (a prim or the Context), unless the error must propagate."""
        if isinstance(exc, Tf.ErrorException):
            corrupt = [line for line in _error_lines(exc, ctx.file) if "Corrupt asset" in line]
            if corrupt:  # a crate value USD unpacks only when a rule reads it
                raise CorruptValue(corrupt[0]) from exc
        if self.raise_errors:
            raise exc
        where = f" on {target.GetPath()}" if isinstance(target, Usd.Prim) else ""
        frame = traceback.extract_tb(exc.__traceback__)[-1]
        detail = " ".join(str(exc).split())  # USD's errors span lines; findings do not
        message = (
            f"rule {rule.code} ({rule.name}) raised {type(exc).__name__}: {detail}{where} "
            f"[{os.path.basename(frame.filename)}:{frame.lineno}]; its other findings on "
            "this file are lost. Please report this."
        )
        return Finding(
            INTERNAL_ERROR_CODE,
            INTERNAL_ERROR_NAME,
            Severity.ERROR,
            message,
            Location(ctx.file, str(target.GetPath()) if where else None),
        )

    def _severity(self, code: str, default: Severity) -> Severity:
        return self.severities.get(code, default)

    def _finding(self, rule: Rule, diagnostic: Diagnostic, ctx: Context) -> Finding:
        finding = Finding(
            code=rule.code,
            name=rule.name,
            severity=self._severity(rule.code, rule.severity),
            message=bounded_message(diagnostic.message),
            location=locate(ctx.stage, ctx.file, diagnostic.at, diagnostic.layer),
            fix=_fix_info(diagnostic.fix),
        )
        if self._fixes is not None and diagnostic.fix is not None:
            self._fixes.setdefault(finding, diagnostic.fix)
        return finding

    def _open_failure_findings(self, path: str, opened: StageOpenResult) -> Iterable[Finding]:
        # Not selectable away: a file that cannot be opened is never a silent pass.
        severity = self._severity(STAGE_OPEN_FAILED_CODE, Severity.ERROR)
        lines = list(opened.errors)
        specific = [line for line in lines if not line.startswith("Failed to open layer")]
        # USD follows the real cause with a generic "Failed to open layer @f@": say it once.
        for line in specific or lines:
            yield Finding(
                STAGE_OPEN_FAILED_CODE,
                STAGE_OPEN_FAILED_NAME,
                severity,
                line,
                Location(path, None, os.path.abspath(path), _line_from_error(line)),
            )


def bounded_message(message: str) -> str:
    """At most MAX_MESSAGE_CHARS of a message: a rule quoting a ten-million-element
    array must not put hundreds of megabytes into every report."""
    if len(message) <= MAX_MESSAGE_CHARS:
        return message
    return f"{message[:MAX_MESSAGE_CHARS]}… ({len(message) - MAX_MESSAGE_CHARS} more characters)"


def _unreadable_reason(path: str) -> str | None:
    """Why ``path`` cannot be handed to USD at all, or None when it can."""
    if not os.path.exists(path):
        return "a broken or looping symbolic link" if os.path.islink(path) else "no such file"
    if os.path.isdir(path):
        return "is a directory"
    if not os.path.isfile(path):
        # A FIFO or a device: opening it can block forever.
        return "not a regular file"
    if not os.access(path, os.R_OK):
        return "permission denied"
    return None


def _line_from_error(text: str) -> int | None:
    """USD's parser errors start ``/path/file.usda:LINE:COL:``."""
    parts = text.split(":")
    for first, second in zip(parts, parts[1:], strict=False):
        if first.endswith(USD_EXTENSIONS) and second.strip().isdigit():
            return int(second)
    return None


def _overrides(rule: Rule, hook: str) -> bool:
    """True unless ``rule``'s hook is the base class's, which yields nothing."""
    return getattr(getattr(rule, hook), "__func__", None) is not getattr(Rule, hook)


def _fix_info(fix: Fix | None) -> FixInfo | None:
    return None if fix is None else FixInfo(fix.description, fix.safe)


def _layer_name(layer: Sdf.Layer) -> str:
    return layer.realPath or layer.identifier


def _spec_stack(obj: Usd.Object) -> list[Sdf.Spec]:
    if isinstance(obj, Usd.Property):
        return list(obj.GetPropertyStack(Usd.TimeCode.Default()))
    if isinstance(obj, Usd.Prim):
        return list(obj.GetPrimStack())
    return []


def locate(
    stage: Usd.Stage,
    file: str,
    at: Usd.Object | Sdf.Path | None,
    layer: Sdf.Layer | None = None,
) -> Location:
    """Where a diagnostic is: its path, the layer of the strongest opinion
    behind it (or ``layer`` when given), and the line there in a ``.usda``."""
    if isinstance(at, Sdf.Path):
        at = stage.GetObjectAtPath(at) or at
    if at is None:
        root = layer or stage.GetRootLayer()
        return Location(file, None, _layer_name(root), None)
    if isinstance(at, Sdf.Path):
        return Location(file, str(at), _layer_name(layer) if layer else None, None)
    specs = _spec_stack(at)
    if layer is not None:
        specs = [s for s in specs if s.layer == layer] or specs
        spec = next(iter(specs), None)
        chosen = layer
    else:
        spec = next(iter(specs), None)
        chosen = spec.layer if spec is not None else None
    line = None
    if spec is not None and chosen is not None and _is_text_file(chosen):
        line = usda_lines.line_of(chosen.realPath, str(spec.path))
    return Location(file, str(at.GetPath()), _layer_name(chosen) if chosen else None, line)


def _is_text_file(layer: Sdf.Layer) -> bool:
    path = layer.realPath
    return bool(path) and layer.GetFileFormat().formatId == "usda" and os.path.isfile(path)
