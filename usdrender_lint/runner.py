"""Turns settings and paths into a Report: rule selection, options, file
discovery and the per-file loop. Shared by the command line and the Python API.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from functools import partial

from .api import Rule
from .config import ConfigError, Settings, build_options
from .engine import USD_EXTENSIONS, Linter
from .execution import lint_paths
from .model import FileResult, Report, Severity
from .registry import Registry, SelectionError, build_registry, matches_any, select_rules


def make_rules(registry: Registry, settings: Settings) -> list[Rule]:
    """Instantiate the selected rules with their validated options."""
    for key in ("select", "ignore", "extend_select", "unfixable"):
        check_selectors(registry, getattr(settings, key) or (), settings.where(key))
    for glob, selectors in settings.per_path_ignores.items():
        check_selectors(registry, selectors, f"{settings.where('per_path_ignores')}.{glob}")
    try:
        chosen = select_rules(
            registry.rules, settings.select, settings.ignore, settings.extend_select
        )
    except SelectionError as exc:
        raise ConfigError(str(exc)) from None
    options = _options_by_code(registry, settings)
    return [rule(options.get(rule.code)) for rule in chosen]


def check_selectors(registry: Registry, selectors: Iterable[str], where: str) -> None:
    """Raise a ConfigError naming ``where`` for a selector that names no rule."""
    for token in selectors:
        if not any(matches_any(rule, [token]) for rule in registry.rules):
            raise ConfigError(f"{where}: {token!r} matches no rule code, code prefix or rule name")


def _options_by_code(registry: Registry, settings: Settings) -> dict[str, object]:
    built = {}
    for key, values in settings.rule_options.items():
        rule = registry.find(key)
        where = f"{settings.source or 'config'}: rules.{key}"
        if rule is None:
            raise ConfigError(f"{where}: no rule has this code or name")
        built[rule.code] = build_options(rule.Options, values, where)
    return built


def severity_overrides(registry: Registry, settings: Settings) -> dict[str, Severity]:
    overrides = {}
    for key, severity in settings.severity.items():
        rule = registry.find(key)
        if rule is None:
            raise ConfigError(
                f"{settings.source or 'config'}: severity.{key}: no rule has this code or name"
            )
        overrides[rule.code] = severity
    return overrides


def make_linter(settings: Settings, registry: Registry | None = None, **kwargs) -> Linter:
    registry = registry or build_registry()
    return Linter(
        make_rules(registry, settings),
        severity_overrides(registry, settings),
        time_sample_cap=settings.time_sample_cap,
        known_rules=registry.rules,
        **kwargs,
    )


def collect_files(paths: Iterable[str]) -> list[str]:
    """Expand directories recursively into USD files (sorted); keep files and
    missing paths as given so the engine reports them."""
    files: list[str] = []
    for path in paths:
        if os.path.isdir(path):
            found = []
            for folder, dirs, names in os.walk(path, followlinks=False):
                dirs.sort()
                found.extend(
                    os.path.join(folder, n) for n in names if n.lower().endswith(USD_EXTENSIONS)
                )
            files.extend(sorted(found))
        else:
            files.append(path)
    seen: set[str] = set()
    unique = []
    for f in files:
        key = os.path.normpath(f)
        if key not in seen:
            seen.add(key)
            unique.append(f)
    return unique


def lint_files(
    linter: Linter,
    files: Sequence[str],
    *,
    settings: Settings | None = None,
    jobs: int = 1,
    timeout: float | None = None,
    progress: bool | None = None,
    variant_combinations: int | None = None,
) -> Report:
    """Lint ``files``; results keep the input order whatever ``jobs`` is.

    With ``jobs > 1`` or a ``timeout`` (seconds) the files go to worker
    processes that rebuild the linter from ``settings`` (see :mod:`.execution`).
    ``variant_combinations`` (--variants) lints each file under up to that many
    variant combinations of its render prims (see :mod:`.variants`).
    """
    factory = partial(make_linter, settings) if settings is not None else None
    if variant_combinations is not None:
        from .variants import VariantExplorer, make_variant_explorer

        linter = VariantExplorer(linter, variant_combinations)
        if settings is not None:
            factory = partial(make_variant_explorer, settings, variant_combinations)
    return Report(
        lint_paths(
            files,
            linter=linter,
            linter_factory=factory,
            jobs=jobs,
            timeout=timeout,
            progress=progress,
        )
    )


def fails(report: Report, fail_on: str) -> bool:
    """True when a finding is at or above the ``fail_on`` threshold."""
    if fail_on == "never":
        return False
    threshold = Severity.parse(fail_on).rank
    return any(f.severity.rank >= threshold for f in report.findings)


__all__ = [
    "FileResult",
    "collect_files",
    "fails",
    "lint_files",
    "make_linter",
    "make_rules",
]
