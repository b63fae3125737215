"""``usdrender-lint merge``: the reports of ``check --shard K/N`` jobs as one."""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import click

from .. import __version__
from ..formatters import FormatOptions
from .check import emit_report
from .loading import import_engine
from .options import (
    config_option,
    isolated_option,
    report_format_option,
    report_output_option,
    setting_options,
    setting_values,
    show_info_option,
    statistics_option,
)
from .output import ToolError, errors_after_report, note

if TYPE_CHECKING:
    from ..config import Settings
    from ..model import Report
    from ..registry import Registry
    from ..running.pipeline import Prepared
    from ..running.report_views import SettingsOf


@click.command()
@click.argument("reports", nargs=-1, required=True, type=click.Path(dir_okay=False))
@report_format_option()
@setting_options("merge")
@show_info_option
@config_option(
    "Judge the merged findings with this file's settings (fail-on, select, ignore, "
    "severity, per-path-ignores, unfixable), as check with it would."
)
@isolated_option
@report_output_option
@statistics_option
def merge(
    reports: tuple[str, ...],
    output_format: str,
    show_info: bool,
    config: tuple[str | None, tuple[str, ...]],
    isolated: bool,
    output_file: str | None,
    statistics: bool,
    **settings: Any,
) -> None:
    """Merge JSON reports (of 'check --shard K/N' jobs) into one report.

    The exit code is that of one check over all the files: 2 when a file could
    not be linted, else 1 when a finding reaches --fail-on, else 0."""
    if "-" in reports:  # as check and spec take it ("./-" names a file)
        raise ToolError("merge reads report files, not standard input ('-'): save it first")
    import_engine()
    from ..config import ConfigError
    from ..running.merge import MergeError, merge_reports
    from ..running.outputs import OutputOnInput, refuse_inputs
    from ..running.pipeline import (
        Request,
        RequestError,
        exit_status,
        finished_by_file,
        prepare,
        rejudged,
    )

    given = setting_values("merge", settings)
    config_path, overrides = config
    try:
        inputs = [*reports, *([config_path] if config_path else [])]
        refuse_inputs([(output_file, "the merged report")], inputs)
    except OutputOnInput as exc:
        raise ToolError(str(exc)) from None
    try:
        report, configuration, where = merge_reports(reports)
        # The configuration decides fail-on and which rules a SARIF report describes.
        request = Request(
            (".",), config=config_path, config_overrides=overrides, isolated=isolated, **given
        )
        prepared = prepare(request)
    except (MergeError, RequestError) as exc:
        raise ToolError(str(exc)) from None
    _note_files_elsewhere(where)
    settings_of = _settings_of(prepared.settings, config_path, overrides, isolated)
    # The configuration asked for judges the files as check under it would: its
    # selection, severities, per-path ignores and unfixable rules (the reports'
    # check may have had others). Without one, each file's as its report records
    # it, which its findings show already; what it makes unfixable and the
    # severities it sets are what a SARIF report describes so.
    recorded = _Recorded(report, where, prepared.registry)
    judge = settings_of or recorded.settings_of
    try:
        if settings_of is not None:
            # Its selection and severities too; a rule the checks did not run
            # has no findings to add.
            _refuse_rules_not_run(report, configuration, settings_of, recorded)
            report = rejudged(report, settings_of, prepared.registry)
        report = finished_by_file(report, judge, prepared.registry)
    except (RequestError, ConfigError) as exc:  # a file's nearest configuration
        raise ToolError(str(exc)) from None
    options = FormatOptions(
        show_info=show_info or prepared.settings.fail_on == "info",
        tool_version=__version__,
        statistics=statistics,
        fixing=bool(report.applied_fixes or report.unapplied_fixes),
        configuration=configuration,
        settings_of=settings_of,
    )
    emit_report(report, output_format, prepared.linter.rules, options, output_file)
    for line in (line for r in report.files for line in r.notes):
        note(line)  # as check said them (a file's skipped variant combinations)
    errors_after_report(
        (r.error or r.file for r in report.errored_files), output_format, output_file
    )
    sys.exit(exit_status(report, prepared.settings.fail_on))


def _note_files_elsewhere(where: Mapping[str, str]) -> None:
    """Say when the files the shard reports name (relative to the folder each
    check ran in) are not found from here but are there: the merged report
    names them as recorded, so SARIF's and the HTML report's locations would
    point into this folder. Shards that ran in another checkout of the same
    tree (another machine's path) name files that are found here: no note."""
    elsewhere: dict[str, int] = {}
    for file, folder in where.items():
        relative = not os.path.isabs(file)
        if relative and not os.path.exists(file) and os.path.exists(os.path.join(folder, file)):
            elsewhere[folder] = elsewhere.get(folder, 0) + 1
    for folder, count in elsewhere.items():
        note(
            f"note: {count:,} file{'s' if count != 1 else ''} the reports name "
            f"{'are' if count != 1 else 'is'} not found from here but in {folder}, where "
            "their checks ran: the merged report names files from this folder (SARIF's and "
            "the HTML report's locations); run merge there"
        )


class _Recorded:
    """The configuration files the reports record for their files
    (``config_file``), found and read again once each. A shard's report
    records its working directory, which its relative paths are relative to;
    without it (or when that folder is not here) they are read from this one.
    One that cannot be found or read is said in a note, never left out silently."""

    def __init__(self, report: Report, where: Mapping[str, str], registry: Registry) -> None:
        self.registry = registry
        #: Each file's (recorded path, its report's working directory).
        self.of_file = {r.file: (r.config, where.get(r.file)) for r in report.files}
        self.found: dict[tuple[str | None, str | None], str | None] = {}
        self.read: dict[str | None, Prepared | None] = {}

    def prepared(self, file: str) -> Prepared | None:
        """The configuration ``file`` was linted under, read again: the
        defaults for a file linted with none; None when it cannot be."""
        from ..running.pipeline import Request, RequestError, prepare

        config, base = self.of_file.get(file, (None, None))
        path = None if config is None else self._path(config, base)
        if config is not None and path is None:
            return None
        if path not in self.read:
            try:
                request = Request((".",), config=path, isolated=path is None)
                self.read[path] = prepare(request, self.registry)
            except RequestError as exc:
                note(f"note: the configuration a report records cannot be read again: {exc}")
                self.read[path] = None
        return self.read[path]

    def settings_of(self, file: str) -> Settings | None:
        """Each file's configuration as the check that linted it records it,
        read again; None for a file linted with none, or one whose configuration
        cannot be read (its findings are left as they are)."""
        if self.of_file.get(file, (None, None))[0] is None:
            return None
        prepared = self.prepared(file)
        return prepared.settings if prepared is not None else None

    def _path(self, config: str, base: str | None) -> str | None:
        if (config, base) not in self.found:
            # Where the check ran first: this folder may hold another file of that name.
            tried = [config] if base is None else [os.path.join(base, config), config]
            found = next((path for path in tried if os.path.isfile(path)), None)
            if found is None:
                count = sum(1 for key in self.of_file.values() if key == (config, base))
                where = f" nor in {base}, where its report was made" if base else ""
                note(
                    f"note: {config}: the configuration file the reports record for "
                    f"{count:,} file{'s' if count != 1 else ''} is not found from here{where}: "
                    "merge cannot read again what it sets (a SARIF report's unfixable rules "
                    "and severities); run merge in the folder the checks ran in"
                )
            self.found[config, base] = found
        return self.found[config, base]


def _refuse_rules_not_run(
    report: Report, digest: str | None, settings_of: SettingsOf, recorded: _Recorded
) -> None:
    """Raise a ToolError when the configuration merge judges the files with
    selects a rule the reports' checks did not run (its findings cannot be
    added, so the merged report would not be check's under it); a note when
    the reports do not tell which rules they ran."""
    from ..running.path_ignores import UNIGNORABLE
    from ..running.pipeline import make_rules

    ran = _rules_run(report, digest, recorded)
    judges = {id(s): s for r in report.files if (s := settings_of(r.file)) is not None}
    registry = recorded.registry
    selected = {type(rule).code for s in judges.values() for rule in make_rules(registry, s)}
    missing = sorted(selected - (ran or {f.code for f in report.findings}) - set(UNIGNORABLE))
    named = ", ".join(missing[:5]) + (", ..." if len(missing) > 5 else "")
    if ran is None:
        if missing:  # a rule with a finding ran
            note(
                f"note: the reports do not tell whether their checks ran {named} (the "
                "configuration files they record, read again, are not what they were linted "
                "with): a rule the configuration selects that they did not run has no findings here"
            )
        return
    if missing:
        raise ToolError(
            f"the configuration selects {len(missing):,} rule{'s' if len(missing) != 1 else ''} "
            f"the checks of these reports did not run ({named}): their findings cannot be "
            "added; lint with that configuration, or merge without it"
        )


def _rules_run(report: Report, digest: str | None, recorded: _Recorded) -> frozenset[str] | None:
    """The codes of the rules the reports' checks ran on every file: those of
    the configuration files they record, read again, when these make the
    reports' configuration digest (a check's own flags, which a report does
    not record, would not). None when that cannot be told."""
    from ..running.merge import configuration_digest, digest_of_parts

    if digest is None:
        return None
    parts: dict[int, Prepared] = {}
    for result in report.files:
        prepared = recorded.prepared(result.file)
        if prepared is None:
            return None
        parts.setdefault(id(prepared), prepared)
    digests = [configuration_digest(p.settings, p.linter.rules) for p in parts.values()]
    # One configuration's digest, or a run split by configuration's (its parts').
    whole = digests if len(digests) == 1 else []
    if not digests or digest not in {*whole, digest_of_parts(digests)}:
        return None
    return frozenset.intersection(
        *(frozenset(rule.code for rule in p.linter.rules) for p in parts.values())
    )


def _settings_of(
    settings: Settings, config_path: str | None, overrides: tuple[str, ...], isolated: bool
) -> SettingsOf | None:
    """What the HTML report reads the files again with: the configuration asked
    for, else each file's nearest (with the inline settings given)."""
    if config_path or isolated:
        return lambda _file: settings
    if overrides:
        from ..running.report_views import nearest_with

        return nearest_with(overrides)
    return None
