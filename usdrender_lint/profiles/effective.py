"""What a profile makes of the rules: the effective set (``rules --profile``)
and how each profile treats one rule (``explain``). Pure data, no pxr."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from ..model import Severity
from ..records import record
from . import PROFILES
from .model import Profile

if TYPE_CHECKING:
    from ..api import Rule


@record(frozen=True)
class EffectiveRule:
    rule: type[Rule]
    #: None when the rule does not run under the profile.
    severity: Severity | None
    #: Why the profile differs from the rule's default ("" when it does not).
    why: str = ""

    @property
    def enabled(self) -> bool:
        return self.severity is not None


def effective(rule: type[Rule], profile: Profile) -> EffectiveRule:
    own = getattr(rule, "profile", None)
    if own is not None:
        if own == profile.name:
            return EffectiveRule(rule, rule.severity)
        return EffectiveRule(rule, None, f"a rule of the {own} profile only")
    change = profile.change_for(rule.code)
    if change is None:
        return EffectiveRule(rule, rule.severity)
    return EffectiveRule(rule, change.severity, f"{change.why} ({change.source})")


def effective_rules(rules: Sequence[type[Rule]], profile: Profile | None) -> list[EffectiveRule]:
    """Every rule with its severity under ``profile`` (None: the defaults)."""
    if profile is None:
        return [EffectiveRule(rule, rule.severity) for rule in rules]
    return [effective(rule, profile) for rule in rules]


#: The generic rules that leave alone what a profile accepts (R2-5), and the
#: Profile fields they read: the severity stays, the rule reports fewer things.
ACCEPTED_BY_RULE: dict[str, tuple[str, ...]] = {
    "CA003": ("runtime_cameras",),
    "CA004": ("camera_types", "runtime_cameras"),
    "PR003": ("product_types",),
    "ST010": ("prim_types",),
    "VA001": ("var_outputs",),
}


def _accepts(rule: type[Rule], profile: Profile) -> str:
    """ "; accepts `A`, `B` (sources)" for what the profile accepts that the
    rule would report, "" for nothing."""
    accepted = [a for field in ACCEPTED_BY_RULE.get(rule.code, ()) for a in getattr(profile, field)]
    if not accepted:
        return ""
    names = ", ".join(f"`{a.name}`" for a in accepted)
    sources = "; ".join(dict.fromkeys(a.source for a in accepted))
    return f"; accepts {names} ({sources})"


def _behaves(rule: type[Rule], profile: Profile) -> str:
    """ "; <what the renderer does> (source)" where the profile says what its
    renderer does about the rule's condition, "" where it does not."""
    behaviour = profile.behaviour_for(rule.code)
    return "" if behaviour is None else f"; {behaviour.what} ({behaviour.source})"


def profile_treatment(rule: type[Rule]) -> list[str]:
    """One line per profile: how it treats ``rule`` and why."""
    lines = []
    for profile in PROFILES.values():
        row = effective(rule, profile)
        notes = f"{_accepts(rule, profile)}{_behaves(rule, profile)}"
        if row.severity is None:
            lines.append(f"{profile.name}: off ({row.why})")
        elif row.why:
            lines.append(f"{profile.name}: {row.severity} ({row.why}){notes}")
        else:
            lines.append(f"{profile.name}: {row.severity}, as by default{notes}")
    return lines
