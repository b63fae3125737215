"""The Python API: lint a file or an open stage from a script or a DCC.

``usdrender_lint.lint_file`` and ``usdrender_lint.lint_stage`` return a
:class:`~usdrender_lint.model.Report` of plain frozen dataclasses, with the
same selection, options, severities and per-path ignores as the command line.
Nothing here imports the command line's dependencies (click, rich), and
nothing writes to the stage or its files.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

from pxr import Usd

from .config import ConfigError, Settings, read_config_file
from .docs import rule_info
from .engine import Linter
from .model import FileResult, Finding, Report
from .registry import Registry, RegistryError, build_registry
from .runner import lint_files, make_linter
from .suppress import apply_path_ignores

ConfigLike = Settings | str | os.PathLike[str] | None


def _settings(
    config: ConfigLike, select: Sequence[str] | None, ignore: Sequence[str] | None
) -> Settings:
    """``config`` (a Settings, a config file path or None for the defaults)
    with ``select`` / ``ignore`` applied as the command-line flags are."""
    if config is None:
        settings = Settings()
    elif isinstance(config, Settings):
        settings = config
    else:
        settings = read_config_file(config)
    return settings.merged(
        select=_tokens(select, "select"),
        ignore=_tokens(ignore, "ignore"),
    )


def _tokens(values: Sequence[str] | None, key: str) -> tuple[str, ...] | None:
    if values is None:
        return None
    if isinstance(values, str):
        values = [values]
    if not all(isinstance(v, str) for v in values):
        raise ConfigError(f"{key}: expected rule codes, prefixes or names, got {values!r}")
    return tuple(v.strip() for value in values for v in value.split(",") if v.strip())


def _finish(report: Report, linter: Linter, settings: Settings, registry: Registry) -> Report:
    report = Report(report.files, tuple(rule_info(type(rule)) for rule in linter.rules))
    return apply_path_ignores(report, settings.per_path_ignores, settings.base_dir, registry.rules)


def lint_file(
    path: str | os.PathLike[str],
    *,
    select: Sequence[str] | None = None,
    ignore: Sequence[str] | None = None,
    config: ConfigLike = None,
    variants: bool = False,
    max_variant_combinations: int = 64,
) -> Report:
    """Lint one USD file.

    ``select`` / ``ignore`` take rule codes, prefixes or names, like the
    flags; ``config`` is a :class:`Settings`, the path of a ``pyproject.toml``
    or ``.usdrender-lint.toml``, or None for the defaults (no file is searched
    for). ``variants`` also lints other variant selections of the render prims
    (see ``--variants``). A file that cannot be linted is a result with
    ``status == "error"``, not an exception; a bad configuration raises
    :class:`ConfigError`, a rule plugin that fails to load :class:`RegistryError`.
    """
    registry = build_registry()
    settings = _settings(config, select, ignore)
    linter = make_linter(settings, registry)
    report = lint_files(
        linter,
        [os.fspath(path)],
        progress=False,
        variant_combinations=max_variant_combinations if variants else None,
    )
    return _finish(report, linter, settings, registry)


def lint_stage(
    stage: Usd.Stage,
    *,
    select: Sequence[str] | None = None,
    ignore: Sequence[str] | None = None,
    config: ConfigLike = None,
    file: str | None = None,
) -> Report:
    """Lint an open stage as it is composed now (unsaved edits included).

    ``file`` names it in the findings (default: the root layer's path or
    identifier); the other arguments are those of :func:`lint_file`.
    """
    registry = build_registry()
    settings = _settings(config, select, ignore)
    linter = make_linter(settings, registry)
    name = file or stage.GetRootLayer().realPath or stage.GetRootLayer().identifier
    findings = tuple(linter.lint_stage(stage, name))
    return _finish(Report((FileResult(name, findings=findings),)), linter, settings, registry)


__all__ = [
    "ConfigError",
    "Finding",
    "RegistryError",
    "Report",
    "Settings",
    "lint_file",
    "lint_stage",
]
