"""One finding's fix applied to a caller's open stage: what the UsdValidation
fixer and the Asset Validator's ``Suggestion`` do.

When the edit target is the layer ``--fix`` would edit and that layer is a
writable file with no unsaved edits, the fix is ``--fix``'s own
(:class:`.session.StageFixer` restricted to this finding): verified by linting
again, written as the minimal text edit of a ``.usda`` (comments and layout
kept; a crate file is rewritten, as ``--fix`` does), and the layer read back
from its file, so it is clean and a later ``Save()`` writes nothing more.

Otherwise (an anonymous layer, a layer with unsaved edits, or an edit
target that is another layer) the fix can only be an Sdf edit of the edit
target in memory; whoever saves that layer writes Sdf's export of it, which
keeps neither comments nor layout. A layer whose file has several hard links
gets no fix at all, as ``--fix`` leaves it alone: the save would split the links;
nor does a .usdz package or a layer inside one, which USD cannot save.
"""

from __future__ import annotations

import os
from collections.abc import Callable

from pxr import Ar, Sdf, Usd

from ..api import Fix
from ..engine import Linter
from ..layers.files import layer_real_path
from ..layers.writing import write_problem
from ..model import Finding
from ..records import record
from .session import FixOptions, StageFixer, _call_fix, _find_layer
from .sources import excluded_reason

TEXT = "text"
SDF = "sdf"


@record(frozen=True)
class SingleFix:
    """What applying one fix did: ``how`` is :data:`TEXT` (written as
    ``--fix``'s edit) or :data:`SDF` (an Sdf edit in memory); ``reason`` says
    why it was not applied."""

    how: str
    reason: str | None = None

    @property
    def applied(self) -> bool:
        return self.reason is None


def same_finding(a: Finding, b: Finding) -> bool:
    """The same finding in two lints of one stage (the file name may differ)."""
    return (a.code, a.location.path, a.message) == (b.code, b.location.path, b.message)


def target_layer(stage: Usd.Stage, finding: Finding, fix: Fix) -> Sdf.Layer | None:
    """The layer ``--fix`` edits for this finding (session.StageFixer's choice)."""
    if fix.layer is not None:
        return fix.layer
    if finding.location.layer is None:
        return stage.GetRootLayer()
    return _find_layer(stage.GetUsedLayers(), finding.location.layer)


def writes_text(stage: Usd.Stage, finding: Finding, fix: Fix, edit_layer: Sdf.Layer) -> bool:
    """Whether fixing into ``edit_layer`` is ``--fix``'s written edit (else an Sdf edit)."""
    target = target_layer(stage, finding, fix)
    return (
        target is not None
        and edit_layer == target
        and not target.dirty
        and target in stage.GetLayerStack(includeSessionLayers=False)
        and write_problem(target) is None
    )


def fix_one(
    linter: Linter,
    stage: Usd.Stage,
    finding: Finding,
    fix: Fix,
    edit_layer: Sdf.Layer | None = None,
    excluded: Callable[[str], bool] | None = None,
) -> SingleFix:
    """Apply ``fix`` (the fix ``linter`` offered for ``finding`` on ``stage``)
    into ``edit_layer`` (default: the layer ``--fix`` edits). ``excluded``: the
    configuration's exclusions (FixOptions.excluded), whose layers ``--fix``
    leaves alone. Never raises for a fix that fails: the result says why."""
    if fix.apply is None:
        return SingleFix(SDF, "the rule offers no automatic fix")
    edit_layer = edit_layer or target_layer(stage, finding, fix)
    if edit_layer is None:
        return SingleFix(SDF, "the layer holding the finding is not open")
    refused = refusal(stage, finding, fix, edit_layer, excluded)
    if refused is not None:
        return SingleFix(SDF, refused)
    if not writes_text(stage, finding, fix, edit_layer):
        failure = _call_fix(fix, stage, edit_layer)
        return SingleFix(SDF, failure)
    fixer = StageFixer(
        linter,
        finding.location.file,
        FixOptions(unsafe=True, excluded=excluded),
        lambda other: same_finding(other, finding),
        callers_stage=True,
    )
    fixer.run(stage)
    if fixer.result.errors:
        return SingleFix(TEXT, fixer.result.errors[0])
    for outcome in fixer.outcomes:
        if outcome.code == finding.code and outcome.path == finding.location.path:
            return SingleFix(TEXT, outcome.reason)
    return SingleFix(TEXT, "the finding is no longer reported on this stage")


def refusal(
    stage: Usd.Stage,
    finding: Finding,
    fix: Fix,
    edit_layer: Sdf.Layer,
    excluded: Callable[[str], bool] | None = None,
) -> str | None:
    """Why :func:`fix_one` refuses to fix into ``edit_layer`` before trying
    (None: it tries): a layer the configuration leaves out, or an Sdf edit of a
    hard-linked file or of a .usdz package. A host asks it before offering a fix
    (UsdValidation's CanApplyFix)."""
    left_out = excluded_reason(stage, edit_layer, excluded)
    if left_out is not None or writes_text(stage, finding, fix, edit_layer):
        return left_out
    return _hard_linked(edit_layer) or _packaged(edit_layer)


def _packaged(layer: Sdf.Layer) -> str | None:
    """Why ``layer`` may not get an Sdf edit: it is a .usdz package or a layer
    inside one, which --fix leaves alone and USD cannot save (SdfLayer refuses
    to write a package layer, so ApplyFix's save and IssueFixer.save() raise)."""
    if layer.anonymous or not (
        layer.GetFileFormat().IsPackage() or Ar.IsPackageRelativePath(layer.identifier)
    ):
        return None
    return write_problem(layer)


def _hard_linked(layer: Sdf.Layer) -> str | None:
    """Why ``layer`` may not get an Sdf edit: its file has several hard links,
    which --fix leaves alone and the save after the edit (ApplyFix saves at
    once) would split, writing Sdf's export under one name only."""
    path = layer_real_path(layer)
    try:
        links = os.stat(path).st_nlink if path and not layer.anonymous else 1
    except OSError:  # a package's member, a file gone: no links to split
        return None
    return write_problem(layer) if links > 1 else None


__all__ = [
    "SDF",
    "TEXT",
    "SingleFix",
    "fix_one",
    "refusal",
    "same_finding",
    "target_layer",
    "writes_text",
]
