"""The Python API: lint a file or an open stage from a script or a DCC.

``usdrender_lint.lint_file`` and ``usdrender_lint.lint_stage`` return a
:class:`~usdrender_lint.model.Report` of plain frozen dataclasses. They build
the same :class:`~.pipeline.Request` the command line does, so every
configuration key (selection, severities, options, per-path ignores, roots,
variants) gives the same findings. Nothing here imports the command line's
dependencies (click, rich), and nothing writes to the stage or its files.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

from pxr import Usd

from ..api import Rule
from ..config import ConfigError, Settings, with_inline
from ..engine import SchemasMissing, plugin_problems
from ..explain import rule_info
from ..model import Finding, Report
from ..registry import RegistryError
from ..settings_table import BY_NAME
from .address_space import schemas_missing
from .discovery import Exclusions, force_excluded
from .pipeline import (
    Outcome,
    Prepared,
    Request,
    RequestError,
    SchemasRefused,
    folder_exclusions,
    prepare,
    run,
)


class SchemaRegistryError(ConfigError):
    """USD's schema registry in this process lacks the render schemas' prim
    definitions (USD could not read them, under a low ``ulimit -v``), so nothing
    can be linted: not a problem of the configuration. A :class:`ConfigError`
    only so that ``except ConfigError`` clauses written before it still catch it."""


ConfigLike = Settings | Mapping[str, Any] | str | os.PathLike[str] | None
#: How a ``config`` table is named in its errors.
CONFIG_TABLE = "config"


def _request(paths: Sequence[str], config: ConfigLike, **overrides: object) -> Request:
    """The pipeline Request of an API call (each override a keyword of the
    settings table's API settings; None: not given). Rule lists are read here
    as the table reads them; the Request's check (pipeline.check_request)
    checks every value as a flag's."""
    given: dict[str, Any] = {}
    for name, value in overrides.items():
        entry = BY_NAME[name]
        assert entry.api, name
        if value is not None:
            tokens = entry.kind == "tokens"
            given[name] = entry.parse(value, f"argument {name}") if tokens else value
    if isinstance(config, Mapping):
        # A table of configuration keys, as [tool.usdrender-lint] holds them.
        config = with_inline(
            Settings(), [config], table_name=CONFIG_TABLE, file_hint="pass the file as config=PATH"
        )
    # No config file is searched for: None means the defaults, as documented.
    return Request(
        tuple(paths),
        config=config,
        isolated=config is None,
        jobs=1,
        timeout=None,
        progress=False,
        **given,
    )


def _with_rules(outcome_report: Report, rules: Sequence[Rule], profile: str | None) -> Report:
    return replace(
        _profile_keyword(outcome_report, profile),
        rules=tuple(rule_info(type(rule)) for rule in rules),
    )


def _profile_keyword(report: Report, profile: str | None) -> Report:
    """A profile chosen by the ``profile`` keyword is named so in each finding's
    ``profile_reason``: the pipeline names it as check's flag (``--profile NAME``),
    which this route has not got (as _raise_as_before renames its messages')."""
    if profile is None:
        return report
    flag, keyword = f"--profile {profile}", f"argument profile = {profile}"
    files = tuple(
        replace(
            result,
            findings=tuple(
                replace(f, profile_reason=keyword) if f.profile_reason == flag else f
                for f in result.findings
            ),
        )
        for result in report.files
    )
    return replace(report, files=files)


#: The API's keywords by the flag the pipeline's messages name them with (every
#: keyword the settings table gives the API, ``variants`` too).
_ARGUMENTS = {entry.flag: entry.name for entry in BY_NAME.values() if entry.api and entry.flag}


def _raise_as_before(exc: RequestError) -> None:
    """The API's documented exceptions: ConfigError, RegistryError for a plugin,
    SchemaRegistryError for USD's schemas. A message about a value passed names
    the keyword, not the command line's flag."""
    cause = exc.__cause__
    if isinstance(cause, RegistryError):
        raise cause from None
    if isinstance(exc, SchemasRefused):
        raise SchemaRegistryError(str(exc)) from None
    message = str(cause if isinstance(cause, ConfigError) else exc)
    flag = message.split(":", 1)[0].split(" ", 1)[0]
    if flag in _ARGUMENTS:
        message = f"argument {_ARGUMENTS[flag]}{message[len(flag) :]}"
    raise ConfigError(message) from None


def lint_file(
    path: str | os.PathLike[str],
    *,
    select: Sequence[str] | None = None,
    ignore: Sequence[str] | None = None,
    config: ConfigLike = None,
    extend_select: Sequence[str] | None = None,
    profile: str | None = None,
    variants: bool | None = None,
    max_variant_combinations: int | None = None,
) -> Report:
    """Lint one USD file (or the USD files of a folder, walked as ``check`` walks it).

    ``select`` / ``ignore`` / ``extend_select`` take rule codes, prefixes or
    names, like the flags; ``profile`` is a renderer profile name or "auto";
    ``config`` is a :class:`Settings`, a table of configuration keys as
    ``[tool.usdrender-lint]`` holds them (``{"severity": {"SE003": "info"}}``;
    relative paths in it are read from the working directory), the path of a
    ``pyproject.toml`` or ``.usdrender-lint.toml``, or None for the defaults
    (no file is searched for). ``variants`` (default: the configuration's) also lints other variant
    selections of the render prims (see ``--variants``). A file that cannot be
    linted is a result with ``status == "error"``, not an exception; a bad
    configuration raises :class:`ConfigError`, a rule plugin that fails to
    load :class:`RegistryError`, a USD whose schema registry lacks the render
    schemas :class:`SchemaRegistryError`.
    """
    try:
        outcome: Outcome = run(
            _request(
                [os.fspath(path)],
                config,
                select=select,
                ignore=ignore,
                extend_select=extend_select,
                profile=profile,
                variants=variants,
                max_variant_combinations=max_variant_combinations,
            )
        )
    except RequestError as exc:
        _raise_as_before(exc)
        raise
    _warn_plugin_problems()
    return _with_rules(outcome.report, outcome.rules, profile)


def lint_stage(
    stage: Usd.Stage,
    *,
    select: Sequence[str] | None = None,
    ignore: Sequence[str] | None = None,
    config: ConfigLike = None,
    extend_select: Sequence[str] | None = None,
    profile: str | None = None,
    file: str | None = None,
) -> Report:
    """Lint an open stage as it is composed now (unsaved edits included).

    ``file`` names it in the findings (default: the root layer's path or
    identifier); the other arguments are those of :func:`lint_file`. The stage
    is linted under its current variant selections only (config ``variants``
    applies to files), and never edited. A ``file`` the configuration's
    ``force-exclude`` leaves out gets no result, as with :func:`lint_file`.
    """
    name = file or stage.GetRootLayer().realPath or stage.GetRootLayer().identifier
    try:
        request = _request(
            [name],
            config,
            select=select,
            ignore=ignore,
            extend_select=extend_select,
            profile=profile,
        )
        prepared = prepare(request)
    except RequestError as exc:
        _raise_as_before(exc)
        raise
    if _force_excluded(prepared, name):
        # As check given the file by name (and lint_file) lints nothing.
        return _with_rules(Report(), prepared.linter.rules, profile)
    # Variants are not explored: that authors selections into the stage's
    # session layer, and this stage is the caller's.
    try:
        linted = prepared.linter.run_stage(stage, name)
    except SchemasMissing as exc:  # as lint_file says it: the run's error
        _raise_as_before(SchemasRefused(schemas_missing(exc)))
        raise
    report = prepared.finish(Report((linted.result,)))
    return _with_rules(report, prepared.linter.rules, profile)


def _force_excluded(prepared: Prepared, name: str) -> bool:
    """Whether the configuration's ``force-exclude`` leaves ``name`` out."""
    exclusions = Exclusions.of(prepared.settings)
    return exclusions.force and force_excluded(name, exclusions, folder_exclusions(prepared))


def _warn_plugin_problems() -> None:
    """USD's plugin registration problems (the command line's notes) as a
    RuntimeWarning each: Python shows one once, a caller may make it an error."""
    for problem in plugin_problems():
        warnings.warn(f"USD plugin registration: {problem}", RuntimeWarning, stacklevel=3)


__all__ = [
    "ConfigError",
    "Finding",
    "RegistryError",
    "Report",
    "SchemaRegistryError",
    "Settings",
    "lint_file",
    "lint_stage",
]
