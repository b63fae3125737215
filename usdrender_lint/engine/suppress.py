"""Suppressions: rules silenced in the data (customData) and per file (config).

USD drops ``#`` comments when it reads a layer and usdc has none, so a prim
says which rules to silence in its metadata instead::

    def RenderSettings "Settings" (
        customData = {
            dictionary usdrender_lint = { string[] ignore = ["SE003"] }
        }
    )

The entry silences those rules on that prim and its properties (not on its
children). An entry that silenced nothing is an unused suppression (UL001).
(``per-path-ignores`` from the configuration are applied by the pipeline, to
the finished report: running/path_ignores.py.)
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Iterable, Sequence

from pxr import Sdf, Usd, Vt

from ..api import Diagnostic, Fix, Rule
from ..model import IGNORE_KEY, Finding
from . import layer_words

#: The customData key path (``usdrender_lint`` dictionary, ``ignore`` entry).
UNUSED_SUPPRESSION_CODE = "UL001"
UNUSED_SUPPRESSION_NAME = "unused-suppression"
#: The word (layer_words.WORDS) a layer's file holds when it can author a suppression.
SUPPRESSION_WORD = IGNORE_KEY.partition(":")[0]


def _names(rule: type[Rule] | Rule) -> set[str]:
    return {rule.code, rule.name, *getattr(rule, "aliases", ())}


def _rule_named(entry: str, rules: Iterable[type[Rule] | Rule]) -> type[Rule] | Rule | None:
    """The rule an entry names by code, name or alias (codes are case-insensitive)."""
    token = entry.strip()
    for rule in rules:
        if token.upper() == rule.code or token.lower() in _names(rule):
            return rule
    return None


def ignore_entries(prim: Usd.Prim) -> tuple[str, ...] | None:
    """The prim's ``usdrender_lint:ignore`` entries, () when it has none, None
    when the value is not a list of strings (a malformed suppression)."""
    value = prim.GetCustomDataByKey(IGNORE_KEY)
    if value is None:
        return ()
    if isinstance(value, str):
        return (value,)
    try:
        entries = tuple(value)
    except TypeError:
        return None
    return entries if all(isinstance(e, str) for e in entries) else None


def _authoring_specs(prim: Usd.Prim) -> list[Sdf.PrimSpec]:
    """The prim specs authoring the ignore key, strongest first."""
    dictionary, _, key = IGNORE_KEY.partition(":")
    found = []
    for spec in prim.GetPrimStack():
        authored = spec.customData.get(dictionary)
        if isinstance(authored, dict) and key in authored:
            found.append(spec)
    return found


def _authoring_layer(prim: Usd.Prim) -> Sdf.Layer | None:
    """The layer of the strongest opinion on the ignore key: where to edit it."""
    specs = _authoring_specs(prim)
    return specs[0].layer if specs else None


def _remove_entry(path: Sdf.Path, entry: str) -> Callable[[Usd.Stage], None]:
    """A fix that drops ``entry`` from the list in the edit target's layer.

    It edits the prim spec itself (through the prim stack, so a spec under
    another path in a referenced layer is found). An emptied list is removed
    unless a weaker layer also authors one, which the empty list must keep
    hiding for the fix to change nothing but the unused entry.
    """
    dictionary, _, key = IGNORE_KEY.partition(":")

    def apply(stage: Usd.Stage) -> None:
        prim = stage.GetPrimAtPath(path)
        target = stage.GetEditTarget().GetLayer()
        specs = _authoring_specs(prim)
        spec = next((s for s in specs if s.layer == target), None)
        if spec is None:
            return
        data = dict(spec.customData)
        ours = dict(data[dictionary])
        remaining = [e for e in ours[key] if e != entry]
        weaker = specs[specs.index(spec) + 1 :]
        if remaining or weaker:
            ours[key] = Vt.StringArray(remaining)
        else:
            del ours[key]
        if ours:
            data[dictionary] = ours
        else:
            del data[dictionary]
        if data:
            spec.SetInfo("customData", data)
        else:
            spec.ClearInfo("customData")

    return apply


class _PrimSuppressions:
    """What one prim silences, and which of its entries silenced something."""

    def __init__(self, prim: Usd.Prim, rules: Sequence[Rule]) -> None:
        self.prim = prim
        self.entries = ignore_entries(prim)
        self.codes = {
            entry: named.code
            for entry in self.entries or ()
            if (named := _rule_named(entry, rules)) is not None
        }
        self.used: set[str] = set()

    def silences(self, code: str) -> bool:
        hits = [entry for entry, named in self.codes.items() if named == code]
        self.used.update(hits)
        return bool(hits)


def apply_data_suppressions(
    stage: Usd.Stage,
    findings: Iterable[Finding],
    rules: Sequence[Rule],
    known_rules: Sequence[type[Rule]] | None = None,
    *,
    suppressing: Iterable[Usd.Prim] | None = None,
    failed: Collection[str] = (),
) -> tuple[list[Finding], list[Diagnostic]]:
    """Drop the findings a prim's customData silences.

    Returns the kept findings and one diagnostic per unused or malformed
    entry (for the unused-suppression rule). ``rules`` are the rules that ran;
    an entry naming a rule in ``known_rules`` (default: the rules that ran) that
    did not run is neither used nor reported, since its rule could not fire.
    ``suppressing`` is every usable prim, in traversal order, that
    :func:`has_suppressions` (the engine collects them in its walk); by default
    the stage is traversed for them. An entry naming a rule in ``failed`` (its
    hook raised, its findings are lost) is not reported either.
    """
    on_prim: dict[Sdf.Path, _PrimSuppressions | None] = {}

    def suppressions(path: Sdf.Path) -> _PrimSuppressions | None:
        if path not in on_prim:
            prim = stage.GetPrimAtPath(path)
            on_prim[path] = _PrimSuppressions(prim, rules) if prim else None
        return on_prim[path]

    kept = []
    for finding in findings:
        prim_path = _prim_path(finding.location.path)
        here = suppressions(prim_path) if prim_path is not None else None
        if here is None or not here.silences(finding.code):
            kept.append(finding)

    if suppressing is None:
        suppressing = [prim for prim in stage.Traverse() if has_suppressions(prim)]
    unused: list[Diagnostic] = []
    for prim in suppressing:
        here = suppressions(prim.GetPath())
        if here is not None:  # always: each is a prim of this stage
            unused.extend(_unused(here, rules, known_rules, failed))
    return kept, unused


def layers_may_suppress(layers: Iterable[Sdf.Layer]) -> bool:
    """False when no layer can author a suppression: their files hold no
    ``usdrender_lint`` key at all, so no prim's customData needs reading."""
    return layer_words.layers_may_hold(layers, SUPPRESSION_WORD)


def has_suppressions(prim: Usd.Prim) -> bool:
    """True when the prim authors the suppression customData (even malformed)."""
    return prim.GetCustomDataByKey(IGNORE_KEY) is not None


def _prim_path(path: str | None) -> Sdf.Path | None:
    """The prim a finding's prim or property path belongs to (None: the stage)."""
    if not path or not Sdf.Path.IsValidPathString(path):
        return None
    prim_path = Sdf.Path(path).GetPrimPath()
    return prim_path if prim_path.IsPrimPath() else None


def _unused(
    here: _PrimSuppressions,
    rules: Sequence[Rule],
    known_rules: Sequence[type[Rule]] | None,
    failed: Collection[str] = (),
) -> Iterable[Diagnostic]:
    layer = _authoring_layer(here.prim)
    if here.entries is None:
        yield Diagnostic(
            message=f"customData '{IGNORE_KEY}' must be a list of rule codes or names (string[]), "
            "so it silences nothing",
            at=here.prim,
            layer=layer,
        )
        return
    if UNUSED_SUPPRESSION_CODE in here.codes.values():
        return  # the prim silences unused-suppression reports themselves
    for entry in here.entries:
        if entry in here.used:
            continue
        ran = here.codes.get(entry)
        if ran in failed:
            continue  # it raised: what it would have reported here is unknown
        if ran is not None:
            reason = f"{ran} reports nothing on this prim"
        elif _rule_named(entry, known_rules if known_rules is not None else rules) is None:
            reason = "no rule has this code or name"
        else:
            continue  # a known rule that was not selected could not fire
        fix = Fix(
            description=f"remove {entry!r} from customData '{IGNORE_KEY}'",
            safe=True,
            apply=_remove_entry(here.prim.GetPath(), entry),
            layer=layer,
        )
        yield Diagnostic(
            message=f"suppression of {entry!r} is unused: {reason}",
            at=here.prim,
            fix=fix,
            layer=layer,
        )


# -- per-path ignores ---------------------------------------------------------------


__all__ = [
    "SUPPRESSION_WORD",
    "UNUSED_SUPPRESSION_CODE",
    "apply_data_suppressions",
    "has_suppressions",
    "layers_may_suppress",
    "ignore_entries",
]
