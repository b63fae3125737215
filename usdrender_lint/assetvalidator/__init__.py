"""usdrender-lint as rules of NVIDIA's Asset Validator (``omniverse-asset-validator``).

Installed with the ``omniverse`` extra, this module is the
``omni.asset_validator`` entry point: the Asset Validator's plugin manager
(its ``_plugins.py``, 1.18) loads :data:`plugin` and calls ``on_startup()``,
which registers one ``BaseRuleChecker`` per usdrender-lint rule (third-party
rules too) in the category :data:`CATEGORY`, named ``UsdRenderLint<Name>``
after the rule's kebab-case name, its docstring the rule's code, name and
documentation. One more checker, :data:`ENGINE_CHECKER`, reports the engine's
own findings (UL001 unused suppressions).

Every checker implements ``CheckStage`` only: the first one called on a stage
lints it once, with the linter ``check`` uses for that file (the configuration
found from its folder, renderer profiles inferred from its settings; see
:mod:`usdrender_lint.running.stage_lints`), and each checker reports its
rule's findings. ``check``'s severities map to the Asset Validator's:
error -> FAILURE (the asset fails the rule), warning -> WARNING, info -> INFO;
a rule that raised (UL000) is an ERROR, the Asset Validator's word for a
failure of the code. A safe fix is a ``Suggestion`` that applies ``--fix``'s
edit (:mod:`usdrender_lint.fixing.single`); unsafe fixes are left to
``usdrender-lint check --fix --unsafe-fixes``, as ``--fix`` leaves them.

Nothing here runs unless the Asset Validator loads it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, ClassVar

from omni.asset_validator import (
    BaseRuleChecker,
    CategoryRuleRegistry,
    IssueSeverity,
    PrimId,
    PropertyId,
    StageId,
    Suggestion,
    register_rule,
)
from pxr import Sdf, Usd

from ..api import Rule
from ..api.docs import rule_doc
from ..engine import TracedFinding
from ..fixing.single import fix_one, refusal, same_finding, target_layer
from ..model import INTERNAL_ERROR_CODE, Finding, Severity
from ..running.stage_lints import CheckedLints

#: The Asset Validator category every usdrender-lint rule is registered in.
CATEGORY = "usdrender-lint"
#: The checker of the engine's own findings (no rule class produces them).
ENGINE_CHECKER = "UsdRenderLintEngine"

_SEVERITIES = {
    Severity.ERROR: IssueSeverity.FAILURE,
    Severity.WARNING: IssueSeverity.WARNING,
    Severity.INFO: IssueSeverity.INFO,
}

#: One lint per stage state, shared by every checker; check's linter per folder;
#: the stages whose lint failed, already reported (one issue per stage).
_CHECKED = CheckedLints()
_CHECK = _CHECKED.checks


def reported(stage: Usd.Stage) -> list[TracedFinding]:
    """The stage's findings as ``check`` reports them (per-path ignores applied;
    none on a file ``force-exclude`` leaves out, as ``check`` lints none)."""
    return _CHECKED.reported(stage)


def checker_name(rule: type[Rule]) -> str:
    """``UsdRenderLint`` + the rule's name in PascalCase (``data-window-malformed``
    -> ``UsdRenderLintDataWindowMalformed``)."""
    return "UsdRenderLint" + "".join(part[:1].upper() + part[1:] for part in rule.name.split("-"))


class UsdRenderLintChecker(BaseRuleChecker):
    """Base of the checkers this plugin registers (never registered itself)."""

    #: The rule codes this checker reports.
    codes: ClassVar[frozenset[str]] = frozenset()
    #: Report the findings of no registered rule (the engine's own).
    engine: ClassVar[bool] = False
    known: ClassVar[frozenset[str]] = frozenset()

    def _mine(self, traced: TracedFinding) -> bool:
        if self.engine:
            return traced.rule_code not in self.known
        return traced.rule_code in self.codes

    def CheckStage(self, usdStage: Usd.Stage) -> None:  # noqa: N802, N803 - the API's names
        try:
            findings = [t for t in reported(usdStage) if self._mine(t)]
        except Exception as exc:  # noqa: BLE001 - one stage's failure is an issue, not a crash
            if _CHECKED.failures.first(usdStage, type(self).__name__):
                self._AddError(
                    message=f"usdrender-lint could not lint the stage: {type(exc).__name__}: {exc}",
                    at=usdStage,
                    code=INTERNAL_ERROR_CODE,
                )
            return
        for traced in findings:
            self._report(usdStage, traced)

    def _report(self, stage: Usd.Stage, traced: TracedFinding) -> None:
        finding, fix = traced.finding, traced.fix
        severity = (
            IssueSeverity.ERROR
            if finding.code == INTERNAL_ERROR_CODE
            else _SEVERITIES[finding.severity]
        )
        suggestion = None
        # A rule the configuration makes ``unfixable`` offers no fix, as --fix applies none;
        # nor does a fix the callable would refuse in its layer (a .usdz package, a
        # hard-linked file, an excluded layer), as UsdValidation's CanApplyFix says no.
        if (
            fix is not None
            and fix.safe
            and fix.apply is not None
            and _CHECK.fixable(stage, finding)
        ):
            layer = target_layer(stage, finding, fix)
            if layer is None or refusal(stage, finding, fix, layer, _CHECK.excluded(stage)) is None:
                suggestion = Suggestion(
                    callable=_FixCallable(finding),
                    message=fix.description,
                    at=[layer] if layer is not None else None,
                )
        issue_kwargs: dict[str, Any] = {
            "message": finding.message,
            "at": _at(stage, finding),
            "code": finding.code,
        }
        if severity is IssueSeverity.INFO:
            self._AddInfo(**issue_kwargs)
        elif severity is IssueSeverity.WARNING:
            self._AddWarning(suggestion=suggestion, **issue_kwargs)
        elif severity is IssueSeverity.ERROR:
            self._AddError(suggestion=suggestion, **issue_kwargs)
        else:
            self._AddFailedCheck(suggestion=suggestion, **issue_kwargs)


class _FixCallable:
    """A Suggestion's callable: the finding's fix on the fixer's stage, into
    the edit target the Asset Validator's IssueFixer set (fixing/single.py)."""

    def __init__(self, finding: Finding) -> None:
        self.finding = finding
        self.__name__ = f"usdrender_lint_fix_{finding.code}"

    def __call__(self, stage: Usd.Stage, at: Any) -> None:
        for traced in reported(stage):
            if same_finding(traced.finding, self.finding) and traced.fix is not None:
                layer = stage.GetEditTarget().GetLayer()
                linter, excluded = _CHECKED.lints.linter(stage), _CHECK.excluded(stage)
                done = fix_one(linter, stage, traced.finding, traced.fix, layer, excluded)
                if not done.applied:
                    # The IssueFixer reports an exception as FixStatus.FAILURE.
                    raise RuntimeError(f"{self.finding.code} not fixed: {done.reason}")
                return
        raise RuntimeError(f"{self.finding.code} is no longer reported on this stage")


def _at(stage: Usd.Stage, finding: Finding) -> Any:
    """The finding's object on the stage: a property, a prim, else the stage.
    A finding seen under other variant selections (the configuration's
    ``variants``) may name an object the stage, as composed now, has not: it
    is named by its path (the Asset Validator's PrimId or PropertyId), as
    ``check`` names it, not by the stage."""
    if finding.location.path:
        path = Sdf.Path(finding.location.path)
        if path.IsPropertyPath():
            prop = stage.GetPropertyAtPath(path)
            if prop:
                return prop
        prim = stage.GetPrimAtPath(path.GetPrimPath())
        if prim:
            return prim
        if finding.variant_selection:
            prim_id = PrimId(stage_id=StageId.from_(stage), path=path.GetPrimPath())
            return PropertyId(prim_id=prim_id, path=path) if path.IsPropertyPath() else prim_id
    return stage


def _doc(rule: type[Rule]) -> str:
    return f"{rule.code} ({rule.name}): {rule.summary() or rule.name}\n\n{rule_doc(rule)}"


def checker_classes(rules: Sequence[type[Rule]]) -> list[type[UsdRenderLintChecker]]:
    """One checker per rule, and the engine's."""
    known = frozenset(rule.code for rule in rules)
    classes: list[type[UsdRenderLintChecker]] = [
        type(
            checker_name(rule),
            (UsdRenderLintChecker,),
            {"__doc__": _doc(rule), "__module__": __name__, "codes": frozenset({rule.code})},
        )
        for rule in sorted(rules, key=lambda r: r.code)
    ]
    engine_doc = (
        "usdrender-lint's own findings: UL001 (unused-suppression), a customData "
        "`usdrender_lint:ignore` entry that silenced nothing or names no rule."
    )
    engine = type(
        ENGINE_CHECKER,
        (UsdRenderLintChecker,),
        {"__doc__": engine_doc, "__module__": __name__, "engine": True, "known": known},
    )
    return [*classes, engine]


def _registered_rules() -> tuple[type[Rule], ...]:
    """Every registered rule; the built-ins when a rule plugin fails to load."""
    from ..registry import RegistryError, build_registry

    try:
        return build_registry().rules
    except RegistryError:
        from ..rules import RULES

        return tuple(RULES)


class UsdRenderLintPlugin:
    """The ``omni.asset_validator`` plugin: registers the checkers on start-up."""

    def __init__(self) -> None:
        self.registered: list[type[UsdRenderLintChecker]] = []

    def on_startup(self) -> None:
        for checker in checker_classes(_registered_rules()):
            register_rule(CATEGORY)(checker)
            self.registered.append(checker)

    def on_shutdown(self) -> None:
        registry = CategoryRuleRegistry()
        for checker in self.registered:
            registry.remove(checker)
        self.registered.clear()


#: The entry point's object.
plugin = UsdRenderLintPlugin()

__all__ = ["CATEGORY", "ENGINE_CHECKER", "UsdRenderLintPlugin", "checker_name", "plugin"]
