"""The ``usdrender-lint`` command: check, rules, explain.

Exit codes: 0 nothing at or above ``--fail-on``; 1 findings at or above it;
2 the tool could not do its job (bad usage or config, a plugin that fails to
load, a path that does not exist, a file it could not lint).
"""

from __future__ import annotations

import gc
import os
import sys
from collections import Counter
from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import click

from . import __version__
from .config import FAIL_ON_CHOICES, ConfigError, load_settings
from .execution import DEFAULT_TIMEOUT, ExecutionError, default_jobs
from .formatters import FormatOptions, available_formatters, load_formatter, reads_rules
from .model import Report

if TYPE_CHECKING:
    from .api import Rule
    from .registry import Registry

EXIT_OK, EXIT_FINDINGS, EXIT_TOOL_ERROR = 0, 1, 2


class ToolError(click.ClickException):
    """A one-line error on stderr and exit 2."""

    exit_code = EXIT_TOOL_ERROR

    def show(self, file=None) -> None:
        click.echo(f"usdrender-lint: error: {self.format_message()}", err=True)


def _split(values: Sequence[str]) -> tuple[str, ...] | None:
    """``--select A,B --select C`` -> ("A", "B", "C"); None when not given."""
    if not values:
        return None
    return tuple(v.strip() for value in values for v in value.split(",") if v.strip())


def _registry() -> Registry:
    _import_engine()
    from .registry import RegistryError, build_registry

    try:
        return build_registry()
    except RegistryError as exc:
        raise ToolError(str(exc)) from None


def _format_choice() -> click.Choice:
    names = sorted(available_formatters()) or ["text", "json"]
    return click.Choice(names, case_sensitive=False)


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="usdrender-lint")
def cli() -> None:
    """Lint OpenUSD render settings (usdRender) before the render farm does."""


@cli.command()
# readable=False: an unreadable file is reported by the engine, and the others
# are still linted, instead of click refusing the whole command.
@click.argument("paths", nargs=-1, required=True, type=click.Path(readable=False))
@click.option(
    "--format",
    "output_format",
    default="text",
    show_default=True,
    type=_format_choice(),
    help="Report format.",
)
@click.option("--select", multiple=True, help="Rules to run: codes, prefixes (CA) or names.")
@click.option("--ignore", multiple=True, help="Rules to skip: codes, prefixes or names.")
@click.option("--extend-select", multiple=True, help="Rules to add to the selection.")
@click.option(
    "--fail-on",
    type=click.Choice(FAIL_ON_CHOICES),
    default=None,
    help="Lowest severity that makes the exit code 1  [default: error].",
)
@click.option("--show-info", is_flag=True, help="Show info findings in the text report.")
@click.option(
    "--config",
    "config_path",
    type=click.Path(dir_okay=False),
    help="Read settings from this file instead of the nearest one.",
)
@click.option("--isolated", is_flag=True, help="Ignore every configuration file.")
@click.option(
    "--no-roots",
    is_flag=True,
    help="Lint PATHS on their own, not inside the stage roots the config names.",
)
@click.option(
    "--jobs",
    "-j",
    type=click.IntRange(min=1),
    default=None,
    help="Files linted in parallel worker processes  [default: the CPU count].",
)
@click.option(
    "--timeout",
    type=click.FloatRange(min=0),
    default=DEFAULT_TIMEOUT,
    show_default=True,
    help="Seconds one file may take before it is reported as an error; 0: no limit.",
)
@click.option(
    "--output",
    "output_file",
    type=click.Path(dir_okay=False),
    help="Write the report to this file (atomically) instead of stdout.",
)
@click.option("--statistics", is_flag=True, help="Add counts per rule code after the report.")
@click.option(
    "--baseline",
    "baseline_file",
    type=click.Path(dir_okay=False),
    help="Report and fail only on findings this baseline file does not record.",
)
@click.option(
    "--write-baseline",
    "write_baseline_file",
    type=click.Path(dir_okay=False),
    help="Record every finding in this baseline file and exit 0.",
)
@click.option("--fix", is_flag=True, help="Apply the safe fixes, then report what remains.")
@click.option(
    "--unsafe-fixes",
    "--unsafe",  # the catalog's spelling
    "unsafe_fixes",
    is_flag=True,
    help="With --fix, --diff or --fix-to: unsafe fixes too.",
)
@click.option(
    "--diff", "show_diff", is_flag=True, help="Print what --fix would change; write nothing."
)
@click.option(
    "--fix-to",
    "fix_to",
    type=click.Path(dir_okay=False),
    help="Write the fixes as overrides into this layer instead of editing the sources.",
)
@click.option(
    "--fix-drop-comments",
    is_flag=True,
    help="Let --fix save a .usda that has comments (saving drops them).",
)
@click.option(
    "--variants",
    is_flag=True,
    default=None,
    help="Also lint under other variant selections of the render prims and their ancestors.",
)
@click.option(
    "--max-variant-combinations",
    type=click.IntRange(min=1),
    default=None,
    help="With --variants: variant combinations linted per file at most  [default: 64].",
)
@click.option(
    "--full-composition",
    is_flag=True,
    hidden=True,
    help="Compose every stage in full, not only what the rules read (same findings, slower).",
)
def check(
    paths: tuple[str, ...],
    output_format: str,
    select: tuple[str, ...],
    ignore: tuple[str, ...],
    extend_select: tuple[str, ...],
    fail_on: str | None,
    show_info: bool,
    config_path: str | None,
    isolated: bool,
    no_roots: bool,
    jobs: int | None,
    timeout: float,
    output_file: str | None,
    statistics: bool,
    baseline_file: str | None,
    write_baseline_file: str | None,
    fix: bool,
    unsafe_fixes: bool,
    show_diff: bool,
    fix_to: str | None,
    fix_drop_comments: bool,
    variants: bool | None,
    max_variant_combinations: int | None,
    full_composition: bool,
) -> None:
    """Lint USD files and directories (recursively: .usd, .usda, .usdc, .usdz)."""
    _import_engine()
    from .engine import FULL_COMPOSITION_ENV
    from .runner import collect_files, fails, lint_files, make_linter
    from .suppress import apply_path_ignores

    if full_composition:
        os.environ[FULL_COMPOSITION_ENV] = "1"  # read by every Linter, in workers too
    registry = _registry()
    try:
        settings = load_settings(config_path, isolated=isolated, start=paths[0])
        settings = settings.merged(
            select=_split(select),
            ignore=_split(ignore),
            extend_select=_split(extend_select),
            fail_on=fail_on,
            variants=variants,
            max_variant_combinations=max_variant_combinations,
        )
        linter = make_linter(settings, registry)
        known = _load_baseline(baseline_file, write_baseline_file)
    except ConfigError as exc:
        raise ToolError(str(exc)) from None

    files = collect_files(paths)
    # With config `roots`, PATHS are linted inside the stages that use them.
    plan = None
    if settings.roots and not no_roots:
        from .roots import plan_from_settings  # USD's dependency tools: only for roots

        plan = plan_from_settings(files, settings)
    fix_options = _fix_options(fix, unsafe_fixes, show_diff, fix_to, fix_drop_comments)
    if settings.variants and fix_options is not None:
        raise ToolError(
            "--variants (or config 'variants') cannot be combined with --fix, --diff or --fix-to"
        )
    fixed = None
    if fix_options is not None:
        fixed = _run_fixes(linter, plan.files if plan else files, fix_options, settings, registry)
    try:
        if fixed is not None and fix_to:
            report = Report(tuple(fixed.remaining))  # what remains with the overrides
        else:
            report = lint_files(
                linter,
                plan.files if plan else files,
                settings=settings,
                jobs=jobs or default_jobs(),
                timeout=timeout,
                variant_combinations=(
                    settings.max_variant_combinations if settings.variants else None
                ),
            )
    except ExecutionError as exc:
        raise ToolError(str(exc)) from None
    if plan is not None:
        report = plan.narrow(report)
    report = type(report)(report.files)
    report = apply_path_ignores(
        report, settings.per_path_ignores, settings.base_dir, registry.rules
    )
    report = _apply_baseline(report, known, baseline_file, write_baseline_file)
    if fixed is not None:
        report = replace(report, applied_fixes=fixed.applied, unapplied_fixes=fixed.unapplied)
    options = FormatOptions(
        show_info=show_info,
        tool_version=__version__,
        statistics=statistics,
        fixing=fixed is not None,
    )
    if show_diff:
        # stdout carries the diff alone; the report goes only to --output.
        click.echo("".join(fixed.diffs), nl=False)
        if output_file:
            _emit_report(report, output_format, linter.rules, options, output_file)
    else:
        _emit_report(report, output_format, linter.rules, options, output_file)
    if fixed is not None:
        _echo_fix_summary(report, show_diff)
    for result in report.errored_files:
        click.echo(f"usdrender-lint: error: {result.error}", err=True)
    if report.errored_files:
        sys.exit(EXIT_TOOL_ERROR)
    if write_baseline_file:
        sys.exit(EXIT_OK)  # today's findings are accepted
    sys.exit(EXIT_FINDINGS if fails(report, settings.fail_on) else EXIT_OK)


def _fix_options(fix: bool, unsafe: bool, show_diff: bool, fix_to: str | None, drop_comments: bool):
    """The fixer's options, or None when no fixing was asked for."""
    if show_diff and fix_to:
        raise ToolError("use either --diff or --fix-to, not both")
    if not (fix or show_diff or fix_to):
        if unsafe or drop_comments:
            flag = "--unsafe-fixes" if unsafe else "--fix-drop-comments"
            raise ToolError(f"{flag} needs --fix, --diff or --fix-to")
        return None
    from .fixer import FixOptions

    return FixOptions(
        unsafe=unsafe, drop_comments=drop_comments, write=not show_diff, fix_to=fix_to
    )


def _run_fixes(linter, files: Sequence[str], options, settings, registry):
    """Apply (or, for --diff, compute) the fixes on every stage, in this process."""
    from .fixer import FixError, fix_files
    from .model import FileResult
    from .registry import matches_any
    from .suppress import apply_path_ignores

    if options.fix_to and len(files) != 1:
        raise ToolError(f"--fix-to writes the overrides of one stage; got {len(files)} files")

    unfixable = {r.code for r in registry.rules if matches_any(r, settings.unfixable)}

    def reported(finding) -> bool:
        # A finding per-path-ignores silence is not fixed either, nor one of an
        # `unfixable` rule.
        if finding.code in unfixable:
            return False
        alone = Report((FileResult(finding.location.file, findings=(finding,)),))
        kept = apply_path_ignores(
            alone, settings.per_path_ignores, settings.base_dir, registry.rules
        )
        return bool(kept.findings)

    try:
        return fix_files(linter, files, options, keep=reported)
    except FixError as exc:
        raise ToolError(str(exc)) from None


def _echo_fix_summary(report: Report, dry_run: bool) -> None:
    """On stderr: each reason a fix was not applied, once, and what was done."""
    by_reason: dict[str, list[str]] = {}
    for fix in report.unapplied_fixes:
        by_reason.setdefault(fix.reason, []).append(fix.code)
    for reason, codes in by_reason.items():
        fixes = "1 fix" if len(codes) == 1 else f"{len(codes)} fixes"
        kinds = ", ".join(sorted(set(codes)))
        click.echo(f"usdrender-lint: {fixes} not applied ({kinds}): {reason}", err=True)
    if dry_run:
        count = len(report.applied_fixes)
        fixes = "1 fix" if count == 1 else f"{count} fixes"
        click.echo(f"usdrender-lint: --diff: {fixes} would be applied", err=True)


def _load_baseline(baseline_file: str | None, write_baseline_file: str | None) -> Counter | None:
    """The baseline's fingerprint counts (None without --baseline); checked
    before linting so a missing or corrupt file fails fast."""
    if baseline_file and write_baseline_file:
        raise ToolError("use either --baseline or --write-baseline, not both")
    if not baseline_file:
        return None
    from .baseline import BaselineError, load_baseline

    try:
        return load_baseline(baseline_file)
    except BaselineError as exc:
        raise ToolError(str(exc)) from None


def _apply_baseline(
    report: Report,
    known: Counter | None,
    baseline_file: str | None,
    write_baseline_file: str | None,
) -> Report:
    """Keep only new findings (--baseline) or record them all (--write-baseline)."""
    if write_baseline_file:
        from .baseline import BaselineError, write_baseline

        try:
            count = write_baseline(report, write_baseline_file)
        except BaselineError as exc:
            raise ToolError(str(exc)) from None
        click.echo(
            f"usdrender-lint: recorded {_findings(count)} in {write_baseline_file}", err=True
        )
    elif known is not None:
        from pathlib import Path

        from .baseline import new_findings

        report, dropped = new_findings(report, known, Path(baseline_file).resolve().parent)
        if dropped:
            click.echo(
                f"usdrender-lint: {_findings(dropped)} recorded in {baseline_file} not shown",
                err=True,
            )
    return report


def _findings(count: int) -> str:
    return f"{count} finding" if count == 1 else f"{count} findings"


def _emit_report(
    report: Report,
    output_format: str,
    rules: Sequence[Rule],
    options: FormatOptions,
    output_file: str | None,
) -> None:
    """Render to stdout, or to ``output_file`` atomically (stdout gets nothing).
    ``rules`` (the rules that ran) are described in the report only for a
    formatter that reads them: building that costs every rule's docstring."""
    formatter = load_formatter(output_format)
    if reads_rules(formatter):
        from .docs import rule_info

        report = replace(report, rules=tuple(rule_info(type(rule)) for rule in rules))
    if output_file is None:
        formatter.render(report, sys.stdout, options)
        return
    import io

    from .atomic import write_text_atomic

    buffer = io.StringIO()
    formatter.render(report, buffer, options)
    try:
        write_text_atomic(output_file, buffer.getvalue())
    except OSError as exc:
        raise ToolError(f"{output_file}: cannot write the report: {exc.strerror or exc}") from None


@cli.command("rules")
@click.option(
    "--format",
    "output_format",
    type=click.Choice(["text", "json"]),
    default="text",
    show_default=True,
)
def list_rules(output_format: str) -> None:
    """List every registered rule."""
    registry = _registry()
    if output_format == "json":
        import json

        rows = [
            {
                "code": r.code,
                "name": r.name,
                "severity": r.severity.value,
                "summary": r.summary(),
                "fix": r.fix_safety,
                "plugin": registry.origins[r.code],
            }
            for r in registry.rules
        ]
        click.echo(json.dumps(rows, indent=2))
        return
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"{len(registry.rules)} rules", title_justify="left")
    for column in ("Code", "Name", "Severity", "Fix"):
        table.add_column(column, no_wrap=True)
    table.add_column("Summary")
    for r in registry.rules:
        table.add_row(r.code, r.name, r.severity.value, r.fix_safety, r.summary())
    Console(soft_wrap=False).print(table)


@cli.command()
@click.argument("rule")
def explain(rule: str) -> None:
    """Print a rule's documentation (by code or name)."""
    from .docs import rule_doc

    found = _registry().find(rule)
    if found is None:
        raise ToolError(f"no rule has the code or name {rule!r} (see 'usdrender-lint rules')")
    header = f"{found.code} {found.name} ({found.severity.value}, fix: {found.fix_safety})"
    click.echo(f"{header}\n\n{rule_doc(found)}")


@cli.command("plugin-path")
@click.option(
    "--write",
    is_flag=True,
    help="(Re)generate plugInfo.json from the registered rules (plugins included).",
)
@click.option(
    "--check", "check_only", is_flag=True, help="Exit 1 when plugInfo.json is out of date."
)
@click.option(
    "--dir",
    "directory",
    type=click.Path(file_okay=False),
    help="Plugin directory to write or check  [default: the one shipped in the package].",
)
def plugin_path(write: bool, check_only: bool, directory: str | None) -> None:
    """Print the UsdValidation plugin directory (for PXR_PLUGINPATH_NAME)."""
    from pathlib import Path

    from .usdplugin import DeclarationError, plugin_dir, undeclared_rules, write_plug_info

    rules = _registry().rules
    folder = Path(directory).resolve() if directory else plugin_dir()
    if write:
        try:
            write_plug_info(rules, folder)
        except (OSError, DeclarationError) as exc:
            raise ToolError(f"{folder}: cannot write plugInfo.json: {exc}") from None
    stale = undeclared_rules(rules, folder)
    click.echo(str(folder))
    if stale:
        click.echo(
            f"usdrender-lint: {folder}/plugInfo.json does not declare {len(stale)} registered "
            f"rule(s) as they are now ({', '.join(stale)}); run 'usdrender-lint plugin-path "
            "--write --dir DIR' and point PXR_PLUGINPATH_NAME at DIR",
            err=True,
        )
        if check_only:
            sys.exit(EXIT_FINDINGS)


def main(argv: Sequence[str] | None = None) -> None:
    """Console entry point: no traceback ever reaches the user."""
    try:
        cli.main(args=argv, prog_name="usdrender-lint", standalone_mode=True)
    except SystemExit:
        raise
    except KeyboardInterrupt:
        click.echo("usdrender-lint: interrupted", err=True)
        sys.exit(130)
    except Exception as exc:
        if os.environ.get("USDRENDER_LINT_DEBUG"):
            raise
        click.echo(
            f"usdrender-lint: internal error: {type(exc).__name__}: {exc} "
            "(set USDRENDER_LINT_DEBUG=1 for a traceback)",
            err=True,
        )
        sys.exit(EXIT_TOOL_ERROR)


def _import_engine() -> None:
    """Import USD and the engine with the cyclic garbage collector paused, then
    freeze what the imports made. Imports make no garbage worth collecting, and
    each collection on the way would walk every object USD created so far
    (about 10 ms of a one-file check); frozen objects are never walked again.
    Called by the commands that need USD: ``--help`` and ``--version`` do not."""
    if "usdrender_lint.runner" in sys.modules:
        return
    enabled = gc.isenabled()
    gc.disable()
    try:
        from . import runner  # noqa: F401 - USD, the engine and the rule API
    finally:
        gc.freeze()
        if enabled:
            gc.enable()
