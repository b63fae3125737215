"""``usdrender-lint merge``: the reports of ``check --shard K/N`` jobs as one."""

from __future__ import annotations

import sys
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
        report, configuration = merge_reports(reports)
        # The configuration decides fail-on and which rules a SARIF report describes.
        request = Request(
            (".",), config=config_path, config_overrides=overrides, isolated=isolated, **given
        )
        prepared = prepare(request)
    except (MergeError, RequestError) as exc:
        raise ToolError(str(exc)) from None
    settings_of = _settings_of(prepared.settings, config_path, overrides, isolated)
    # The configuration asked for judges the files as check under it would: its
    # per-path ignores and unfixable rules (the reports' check may have had others).
    # Without one, each file's as its report records it, which its findings show
    # already; what it makes unfixable is what a SARIF report describes so.
    judge = settings_of or _recorded(report, prepared.registry)
    try:
        if settings_of is not None:
            # Its selection and severities too; a rule the checks did not run
            # has no findings to add.
            _refuse_rules_not_run(report, configuration, settings_of, prepared.registry)
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


def _recorded(report: Report, registry: Registry) -> SettingsOf:
    """Each file's configuration as the check that linted it records it
    (``config_file``), read again; None for a file linted with none, or one
    whose configuration is not here to read (its findings are left as they are)."""
    from ..running.pipeline import Request, RequestError, prepare

    recorded = {result.file: result.config for result in report.files}
    known: dict[str, Settings | None] = {}

    def settings_of(file: str) -> Settings | None:
        config = recorded.get(file)
        if config is None:
            return None
        if config not in known:
            try:
                known[config] = prepare(Request((".",), config=config), registry).settings
            except RequestError:
                known[config] = None
        return known[config]

    return settings_of


def _refuse_rules_not_run(
    report: Report, digest: str | None, settings_of: SettingsOf, registry: Registry
) -> None:
    """Raise a ToolError when the configuration merge judges the files with
    selects a rule the reports' checks did not run (its findings cannot be
    added, so the merged report would not be check's under it); a note when
    the reports do not tell which rules they ran."""
    from ..running.path_ignores import UNIGNORABLE
    from ..running.pipeline import make_rules

    ran = _rules_run(report, digest, registry)
    judges = {id(s): s for r in report.files if (s := settings_of(r.file)) is not None}
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


def _rules_run(report: Report, digest: str | None, registry: Registry) -> frozenset[str] | None:
    """The codes of the rules the reports' checks ran on every file: those of
    the configuration files they record (``config_file``), read again, when
    these make the reports' configuration digest (a check's own flags, which
    a report does not record, would not). None when that cannot be told."""
    from ..running.merge import configuration_digest, digest_of_parts
    from ..running.pipeline import Request, RequestError, prepare

    if digest is None:
        return None
    digests: list[str] = []
    ran: list[frozenset[str]] = []
    for config in sorted({r.config for r in report.files}, key=lambda c: c or ""):
        request = Request((".",), config=config, isolated=config is None)
        try:
            prepared = prepare(request, registry)
        except RequestError:
            return None
        digests.append(configuration_digest(prepared.settings, prepared.linter.rules))
        ran.append(frozenset(rule.code for rule in prepared.linter.rules))
    # One configuration's digest, or a run split by configuration's (its parts').
    if not ran or digest not in {*digests[:1], digest_of_parts(digests)}:
        return None
    return frozenset.intersection(*ran)


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
