"""The UsdValidation validators: each rule's findings as ``ValidationError``s.

A validator does not run its rule alone: the rules share a per-stage Context
(render configurations, memoised helpers) and the engine's customData
suppressions, so the first validator called on a stage lints it once
(:meth:`Linter.run_stage`: its LintRun traces each finding to its rule and
prim), and each validator reports the findings its rule produced: a prim
validator those of ``check_prim`` on that prim, a stage validator those of
``check_stage`` and the engine's own (UL001). The cached lint is dropped when
the stage changes. The lint is ``check``'s for the stage's file, as the Asset
Validator's (running/stage_lints.py): the configuration found from its folder
(select, ignore, severities, options, profiles, per-path ignores, variants,
force-exclude), and a fixer applies no fix ``check --fix`` would not
(``unfixable``, ``variants``, excluded layers).

usd-core 26.11 turns an exception raised by a Python validator into an error
that makes the whole ``ValidationContext.Validate`` call raise and lose every
other validator's results, so nothing here lets an exception out: a failure
becomes a ``ValidationError`` of the validator that failed.
"""

from __future__ import annotations

import traceback
from typing import Any

from pxr import Sdf, Tf, Usd, UsdValidation

from ..api import Fix, Rule
from ..engine import TracedFinding
from ..fixing.single import fix_one, refusal
from ..model import Finding, Severity
from ..running.pipeline import RequestError
from ..running.stage_lints import CheckedLints
from . import PLUGIN_NAME, is_prim_validator, validator_key, validator_name

ErrorType = UsdValidation.ValidationErrorType
_ERROR_TYPES = {
    Severity.ERROR: ErrorType.Error,
    Severity.WARNING: ErrorType.Warn,
    Severity.INFO: ErrorType.Info,
}
#: Error name of a validator that could not do its job.
FAILURE_ERROR_NAME = "usdRenderLintFailure"
STALE_REASON = (
    "no registered rule has this validator name; regenerate the plugInfo.json "
    "(usdrender-lint plugin-path --write)"
)


def _site(stage: Usd.Stage, finding: Finding) -> UsdValidation.ValidationErrorSite:
    """The finding's prim or property (the pseudo-root for stage-wide findings),
    in the layer holding the opinion behind it when that layer is open."""
    path = Sdf.Path(finding.location.path) if finding.location.path else Sdf.Path.absoluteRootPath
    layer = Sdf.Layer.Find(finding.location.layer) if finding.location.layer else None
    if layer is not None:
        return UsdValidation.ValidationErrorSite(stage, path, layer)
    return UsdValidation.ValidationErrorSite(stage, path)


def to_error(stage: Usd.Stage, finding: Finding) -> UsdValidation.ValidationError:
    """A finding as a ValidationError named by its code (UL000: the rule raised)."""
    return UsdValidation.ValidationError(
        finding.code,
        _ERROR_TYPES[finding.severity],
        [_site(stage, finding)],
        finding.message,
    )


def failure_error(stage: Any, rule: type[Rule] | None, exc: BaseException) -> Any:
    """The one error a validator reports when it could not run."""
    frame = traceback.extract_tb(exc.__traceback__)[-1:] if exc.__traceback__ else []
    where = f" [{frame[0].filename.rsplit('/', 1)[-1]}:{frame[0].lineno}]" if frame else ""
    what = f"{rule.code} ({rule.name})" if rule is not None else "usdrender-lint"
    message = f"{what} could not run: {type(exc).__name__}: {exc}{where}"
    try:
        sites = [UsdValidation.ValidationErrorSite(stage, Sdf.Path.absoluteRootPath)]
    except Exception:  # noqa: BLE001 - e.g. the stage has expired
        sites = []
    return UsdValidation.ValidationError(FAILURE_ERROR_NAME, ErrorType.Error, sites, message)


def config_error(stage: Any, exc: RequestError) -> Any:
    """The one error of a stage whose configuration (or a rule plugin) cannot
    be loaded: the line ``check`` prints for it."""
    sites = [UsdValidation.ValidationErrorSite(stage, Sdf.Path.absoluteRootPath)]
    message = f"usdrender-lint could not lint the stage: {exc}"
    return UsdValidation.ValidationError(FAILURE_ERROR_NAME, ErrorType.Error, sites, message)


class RuleValidator:
    """The task functions of one rule's validator and its fixer."""

    def __init__(self, rule: type[Rule], lints: CheckedLints) -> None:
        self.rule = rule
        self.lints = lints

    def _mine(self, stage: Usd.Stage, prim_path: Sdf.Path | None) -> list[TracedFinding]:
        """The rule's findings from ``prim_path``'s check_prim (None: all of them)."""
        return [
            traced
            for traced in self.lints.reported(stage)
            if traced.rule_code == self.rule.code
            and (prim_path is None or traced.prim_path == prim_path)
        ]

    def _errors(self, stage: Usd.Stage, prim_path: Sdf.Path | None) -> list[Any]:
        try:
            return [to_error(stage, t.finding) for t in self._mine(stage, prim_path)]
        except RequestError as exc:
            # A bad configuration is one error per stage, not one per validator.
            first = self.lints.failures.first(stage, (self.rule.code, prim_path))
            return [config_error(stage, exc)] if first else []
        except Exception as exc:  # noqa: BLE001 - see the module docstring
            return [failure_error(stage, self.rule, exc)]

    def validate_stage(self, stage: Usd.Stage, time_range: Any = None) -> list[Any]:
        # A stage validator reports every finding of its rule: those of check_stage
        # and, for a rule with both hooks (is_prim_validator), those of check_prim.
        return self._errors(stage, None)

    def validate_prim(self, prim: Usd.Prim, time_range: Any = None) -> list[Any]:
        try:
            stage = prim.GetStage()
            path = prim.GetPath()
        except Exception as exc:  # noqa: BLE001 - see the module docstring
            return [failure_error(prim.GetStage(), self.rule, exc)]
        return self._errors(stage, path)

    # -- fixer ----------------------------------------------------------------

    def _safe_fix(self, error: Any) -> tuple[Usd.Stage, Finding, Fix] | None:
        """The stage, finding and fix behind ``error`` when its fix is safe and
        ``check --fix`` would apply it (not an ``unfixable`` rule's, nor under a
        configuration that sets ``variants``)."""
        sites = error.GetSites()
        if not sites or error.GetName() != self.rule.code:
            return None
        stage = sites[0].GetStage()
        if stage is None:
            return None
        for traced in self.lints.reported(stage):
            finding, fix = traced.finding, traced.fix
            if (
                finding.code == self.rule.code
                and finding.message == error.GetMessage()
                and Sdf.Path(finding.location.path or "/") == _site_path(sites[0])
                and fix is not None
                and fix.safe
                and fix.apply is not None
            ):
                return (stage, finding, fix) if self.lints.checks.fixable(stage, finding) else None
        return None

    def can_apply(self, error: Any, edit_target: Usd.EditTarget, time_code: Any = None) -> bool:
        """Whether ``apply`` would fix into this edit target: a safe fix, and a
        layer ``apply`` does not refuse (a .usdz package, a hard-linked file)."""
        try:
            found = self._safe_fix(error)
            if found is None:
                return False
            stage, finding, fix = found
            layer = edit_target.GetLayer()
            excluded = self.lints.checks.excluded(stage)
            return layer is not None and refusal(stage, finding, fix, layer, excluded) is None
        except Exception:  # noqa: BLE001 - see the module docstring
            return False

    def apply(self, error: Any, edit_target: Usd.EditTarget, time_code: Any = None) -> bool:
        """Apply the rule's safe fix into the caller's edit target: ``--fix``'s
        text edit when that is the layer ``--fix`` edits (fixing/single.py),
        else an Sdf edit (ApplyFix then saves the layer through Sdf)."""
        try:
            found = self._safe_fix(error)
            if found is None:
                return False
            stage, finding, fix = found
            previous = stage.GetEditTarget()
            try:
                checks = self.lints.checks
                linter, excluded = checks.linter(stage), checks.excluded(stage)
                done = fix_one(linter, stage, finding, fix, edit_target.GetLayer(), excluded)
            finally:
                stage.SetEditTarget(previous)
            return done.applied
        except Exception:  # noqa: BLE001 - see the module docstring
            return False

    def fixers(self) -> list[Any]:
        """A ValidationFixer when the rule can have a safe fix."""
        if self.rule.fix_safety not in ("safe", "safe-conditional"):
            return []
        return [
            UsdValidation.ValidationFixer(
                name=f"{validator_key(self.rule)}Fix",
                description=fixer_description(self.rule),
                fixerImplFn=self.apply,
                canApplyFn=self.can_apply,
                keywords=[PLUGIN_NAME],
                errorName=self.rule.code,
            )
        ]


def fixer_description(rule: type[Rule]) -> str:
    return (
        f"Apply the safe fix of {rule.code} ({rule.name}). With the edit target on the "
        "layer `usdrender-lint check --fix` edits (a writable file without unsaved edits), "
        "it is --fix's edit: verified, written as a minimal text edit of a .usda (comments "
        "and layout kept), the layer left clean. With any other edit target it can only be "
        "an Sdf edit, which ApplyFix saves through Sdf (comments and layout not kept)."
    )


def _site_path(site: Any) -> Sdf.Path:
    if site.IsProperty():
        return site.GetProperty().GetPath()
    if site.IsPrim():
        return site.GetPrim().GetPath()
    return Sdf.Path.absoluteRootPath


class UnavailableValidator:
    """A declared validator whose rule is not registered (a stale plugInfo.json
    or a rule plugin that fails to load): it reports why instead of failing to load."""

    def __init__(self, name: str, reason: str) -> None:
        self.name = name
        self.reason = reason

    def validate_stage(self, stage: Usd.Stage, time_range: Any = None) -> list[Any]:
        try:
            site = UsdValidation.ValidationErrorSite(stage, Sdf.Path.absoluteRootPath)
            return [
                UsdValidation.ValidationError(
                    FAILURE_ERROR_NAME, ErrorType.Error, [site], f"{self.name}: {self.reason}"
                )
            ]
        except Exception:  # noqa: BLE001 - see the module docstring
            return []

    def validate_prim(self, prim: Usd.Prim, time_range: Any = None) -> list[Any]:
        # Once per stage: on its pseudo-root or, with schema types, nowhere useful.
        return self.validate_stage(prim.GetStage()) if prim.IsPseudoRoot() else []


def register_validators(usd_registry: Any = None) -> list[str]:
    """Register a task function (and fixer) for every validator this plugin
    declares; returns the names registered. Never raises."""
    registered: list[str] = []
    try:
        usd_registry = usd_registry or UsdValidation.ValidationRegistry()
        declared = [
            str(m.name)
            for m in usd_registry.GetValidatorMetadataForPlugin(PLUGIN_NAME)
            if not usd_registry.HasValidator(m.name)
        ]
        rules, reason = _registered_rules()
        lints = CheckedLints()
        by_name = {validator_name(rule): rule for rule in rules}
        for name in declared:
            metadata = usd_registry.GetValidatorMetadata(name)
            rule = by_name.get(name)
            task: UnavailableValidator | RuleValidator
            if rule is None:
                task = UnavailableValidator(name, reason or STALE_REASON)
                prim = bool(metadata.GetSchemaTypes())
                fixers: list[Any] = []
            else:
                task = RuleValidator(rule, lints)
                prim = is_prim_validator(rule)
                fixers = task.fixers()
            if prim:
                usd_registry.RegisterPluginPrimValidator(name, task.validate_prim, fixers)
            else:
                usd_registry.RegisterPluginStageValidator(name, task.validate_stage, fixers)
            registered.append(name)
    except Exception as exc:  # noqa: BLE001 - a failing import would fail every validator
        Tf.Warn(f"usdrender-lint: validators not registered: {type(exc).__name__}: {exc}")
    return registered


def _registered_rules() -> tuple[tuple[type[Rule], ...], str | None]:
    """Every registered rule; when a rule plugin fails to load, the built-ins
    and the reason the others are missing."""
    from ..registry import RegistryError, build_registry

    try:
        return build_registry().rules, None
    except RegistryError as exc:
        from ..engine.suppress import UNUSED_SUPPRESSION_CODE
        from ..rules import RULES

        # Not UL001: the missing plugins' entries would be "no rule has this code
        # or name", with a safe fix deleting the suppressions of working rules.
        rules = tuple(rule for rule in RULES if rule.code != UNUSED_SUPPRESSION_CODE)
        return rules, f"usdrender-lint rule plugins failed to load: {exc}"
