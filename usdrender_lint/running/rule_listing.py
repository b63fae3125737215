"""The rules a ``check`` run from the working directory would run, for ``rules``:
the configuration's selection, severities and profile, under a profile the
command names or the one the configuration sets."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from ..config import ConfigError, Settings, with_key_line
from ..profiles import get_profile
from ..profiles.effective import EffectiveRule, effective_rules
from ..records import record
from ..registry import matches_any
from .pipeline import (
    Request,
    RequestError,
    check_profiles,
    check_working_directory,
    make_rules,
    resolve_settings,
    severity_overrides,
)

if TYPE_CHECKING:
    from ..api import Rule
    from ..profiles.model import Profile
    from ..registry import Registry


@record(frozen=True)
class ConfiguredRules:
    rows: Sequence[EffectiveRule]
    #: The profile the rows are judged under (None: no single one).
    profile: Profile | None
    #: Whether a configuration file or a flag chose the rows (not the defaults alone).
    configured: bool
    notes: tuple[str, ...] = ()


def configured_rules(registry: Registry, request: Request) -> ConfiguredRules:
    """Every rule of ``registry`` as ``check`` of ``request`` would run it
    (its configuration found as check finds it, its flags over it): off where
    select/ignore/extend-select leave it out, at the configured severity where
    ``severity`` sets one (it wins over the profile's, as in the engine), under
    the request's ``profile`` or else the configuration's (``auto`` and
    per-path-profiles choose one per file: none then). A bad configuration is
    a RequestError worded as check words it."""
    settings: Settings | None = None
    try:
        if not request.isolated and request.config is None:
            check_working_directory()  # the configuration is searched for from it
        settings = resolve_settings(request)
        check_profiles(settings)
        chosen = {rule.code for rule in make_rules(registry, settings)}
        overrides = severity_overrides(registry, settings)
    except ConfigError as exc:
        message = str(exc) if settings is None else with_key_line(str(exc), settings)
        raise RequestError(message) from None
    notes: list[str] = []
    given = "profile" in settings.from_flags
    name = settings.profile if settings.profile != "auto" else None
    if not given and settings.per_path_profiles:
        notes.append(
            f"note: {settings.where('per_path_profiles')} chooses a profile per file: "
            "--profile NAME shows the rules under one"
        )
    chosen_profile = get_profile(name) if name is not None else None
    rows = []
    for row in effective_rules(registry.rules, chosen_profile):
        code = row.rule.code
        if code not in chosen:
            row = EffectiveRule(row.rule, None, _left_out(settings, row.rule))
        elif row.severity is not None and code in overrides:
            where = _severity_where(settings, registry, code)
            why = f"{row.why}; " if row.why else ""
            row = EffectiveRule(row.rule, overrides[code], f"{why}severity set by {where}")
        rows.append(row)
    configured = bool(settings.sources or settings.from_flags or settings.from_file)
    return ConfiguredRules(rows, chosen_profile, configured, tuple(notes))


def _left_out(settings: Settings, rule: type[Rule]) -> str:
    """Which setting leaves ``rule`` out: the nearest layer's ``ignore`` that
    names it, else the nearest ``select`` (each starts over: select_rules)."""
    for layer in reversed(settings.selection_layers):
        if matches_any(rule, layer.ignore):
            return f"ignored by {layer.origins['ignore']}"
        if layer.select is not None:
            return f"not selected by {layer.origins['select']}"
    return "not selected"


def _severity_where(settings: Settings, registry: Registry, code: str) -> str:
    """The entry of ``severity`` that sets ``code``'s (the last, as the engine reads them)."""
    keys = [key for key in settings.severity if getattr(registry.find(key), "code", None) == code]
    return f"{settings.where_entry('severity', keys[-1])}.{keys[-1]}"
