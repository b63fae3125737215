"""The ``usdrender-lint`` command: check, merge, spec, rules, explain.

Exit codes: 0 nothing at or above ``--fail-on``; 1 findings at or above it;
2 the tool could not do its job (bad usage or config, a plugin that fails to
load, a path that does not exist, a file it could not lint).
"""

from __future__ import annotations

import gc
import os
import sys
from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import click

from . import __version__
from .config import (
    FAIL_ON_CHOICES,
    ConfigError,
    check_jobs,
    check_max_variant_combinations,
    check_timeout,
    load_settings,
)
from .formatters import (
    FormatOptions,
    available_formatters,
    escaped,
    load_formatter,
    reads_rules,
)
from .model import Report
from .paths import escape, printable
from .running import read_ahead as _read_ahead
from .running import supervisor
from .running.interrupts import Stopped, check_stopped, stop_on_signals
from .running.workers import DEFAULT_TIMEOUT, limit_supervised_memory

if TYPE_CHECKING:
    from pathlib import Path

    from .api import Rule
    from .registry import Registry

#: The pipeline's exit codes (running/pipeline.py), repeated so that --help
#: and --version need no import of USD.
EXIT_OK, EXIT_FINDINGS, EXIT_TOOL_ERROR = 0, 1, 2


class ToolError(click.ClickException):
    """A one-line error on stderr and exit 2."""

    exit_code = EXIT_TOOL_ERROR

    def show(self, file=None) -> None:
        _error(self.format_message())


class StdoutGone(Exception):
    """stdout is closed, or its reader went away (``check | head``): nobody
    reads the report, so the run ends with exit 2 and says nothing."""


def _error(message: str) -> None:
    click.echo(f"usdrender-lint: error: {printable(message)}", err=True)


class _Stdout:
    """sys.stdout, written to the end: the text is gathered and written with
    :func:`~.atomic.write_all` (a single ``write()`` to a pipe whose reader
    left takes part of it and says nothing, so Python's own stream could
    leave a report cut short with exit 0). A closed or broken pipe is
    :class:`StdoutGone`, any other failure (a full disk) a ToolError."""

    #: Bytes gathered before they are written.
    CHUNK = 1 << 16

    def __init__(self) -> None:
        self._parts: list[str] = []
        self._size = 0

    def write(self, text: str) -> int:
        self._parts.append(text)
        self._size += len(text)
        if self._size >= self.CHUNK:
            self.flush()
        return len(text)

    def flush(self) -> None:
        text, self._parts, self._size = "".join(self._parts), [], 0
        self._do(text)

    def isatty(self) -> bool:
        return bool(sys.stdout is not None and sys.stdout.isatty())

    @staticmethod
    def _do(text: str) -> None:
        from .atomic import write_all

        stream = sys.stdout
        if stream is None:  # fd 1 was closed when Python started
            raise StdoutGone
        try:
            stream.flush()
            try:
                fd = stream.fileno()
            except (AttributeError, ValueError, OSError):  # not a file (a test's capture)
                stream.write(text)
                stream.flush()
                return
            write_all(fd, text.encode(stream.encoding or "utf-8", stream.errors or "strict"))
        except BrokenPipeError:
            raise StdoutGone from None
        except OSError as exc:
            raise ToolError(f"cannot write the report: {exc.strerror or exc}") from None


def _write(text: str) -> None:
    """Write ``text`` to stdout and flush it, so that a failure is known now."""
    stdout = _Stdout()
    stdout.write(text)
    stdout.flush()


class _Checked(click.ParamType):
    """A number checked by the configuration's own range check (config.py):
    a value out of range is a usage error, exit 2."""

    def __init__(self, base: click.ParamType, check) -> None:
        self.base = base
        self.check = check
        self.name = base.name

    def convert(self, value, param, ctx):
        number = self.base.convert(value, param, ctx)
        try:
            return self.check(number, "it")
        except ConfigError as exc:
            self.fail(str(exc), param, ctx)


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


def _profile_choices() -> list[str]:
    from .profiles import AUTO, profile_names  # data only: no USD import

    return [AUTO, *profile_names()]


def _format_choice() -> click.Choice:
    names = sorted(available_formatters()) or ["text", "json"]
    return click.Choice(names, case_sensitive=False)


#: Options several commands take, defined once so they read and check alike.
_report_format_option = click.option(
    "--format",
    "output_format",
    default="text",
    show_default=True,
    type=_format_choice(),
    help="Report format.",
)
_show_info_option = click.option(
    "--show-info", is_flag=True, help="Show info findings in the text report."
)
_isolated_option = click.option("--isolated", is_flag=True, help="Ignore every configuration file.")
_report_output_option = click.option(
    "--output",
    "output_file",
    type=click.Path(dir_okay=False),
    help="Write the report to this file (atomically) instead of stdout.",
)
_statistics_option = click.option(
    "--statistics", is_flag=True, help="Add counts per rule code after the report."
)
_profile_option = click.option(
    "--profile",
    type=click.Choice(_profile_choices()),
    default=None,
    help="Renderer profile: auto (inferred per RenderSettings) or a name  [default: auto].",
)
_jobs_option = click.option(
    "--jobs",
    "-j",
    type=_Checked(click.INT, check_jobs),
    default=None,
    help="Files linted in parallel worker processes  [default: the CPU count].",
)
_timeout_option = click.option(
    "--timeout",
    type=_Checked(click.FLOAT, check_timeout),
    default=DEFAULT_TIMEOUT,
    show_default=True,
    help="Seconds one file may take before it is reported as an error; 0: no limit.",
)


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="usdrender-lint")
def cli() -> None:
    """Lint OpenUSD render settings (usdRender) before the render farm does."""


@cli.command()
# readable=False: an unreadable file is reported by the engine, and the others
# are still linted, instead of click refusing the whole command.
@click.argument("paths", nargs=-1, required=True, type=click.Path(readable=False))
@_report_format_option
@click.option("--select", multiple=True, help="Rules to run: codes, prefixes (CA) or names.")
@click.option("--ignore", multiple=True, help="Rules to skip: codes, prefixes or names.")
@click.option("--extend-select", multiple=True, help="Rules to add to the selection.")
@click.option(
    "--fail-on",
    type=click.Choice(FAIL_ON_CHOICES),
    default=None,
    help="Lowest severity that makes the exit code 1  [default: error].",
)
@_show_info_option
@click.option(
    "--config",
    "config_path",
    type=click.Path(dir_okay=False),
    help="Read settings from this file instead of the nearest one.",
)
@_isolated_option
@click.option(
    "--no-roots",
    is_flag=True,
    help="Lint PATHS on their own, not inside the stage roots the config names.",
)
@_jobs_option
@_timeout_option
@_report_output_option
@_statistics_option
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
    help="No effect: fixes always keep a layer's comments (accepted for old scripts).",
)
@click.option(
    "--variants",
    is_flag=True,
    default=None,
    help="Also lint under other variant selections of the render prims and their ancestors.",
)
@click.option(
    "--max-variant-combinations",
    type=_Checked(click.INT, check_max_variant_combinations),
    default=None,
    help="With --variants: variant combinations linted per file at most  [default: 64].",
)
@_profile_option
@click.option(
    "--full-composition",
    is_flag=True,
    hidden=True,
    help="Compose every stage in full, not only what the rules read (same findings, slower).",
)
@click.option(
    "--no-cache",
    is_flag=True,
    envvar="USDRENDER_LINT_NO_CACHE",
    help="Lint every file, neither reading nor writing the result cache.",
)
@click.option(
    "--cache-dir",
    type=click.Path(file_okay=False),
    envvar="USDRENDER_LINT_CACHE_DIR",
    help="The result cache's folder  [default: .usdrender_lint_cache at the project root].",
)
@click.option(
    "--shard",
    metavar="K/N",
    callback=lambda _ctx, _param, value: _shard(value),
    help="Lint only part K of N of the files (a CI matrix job); see 'merge'.",
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
    fix_drop_comments: bool,  # no effect (see its help)
    variants: bool | None,
    max_variant_combinations: int | None,
    profile: str | None,
    full_composition: bool,
    no_cache: bool,
    cache_dir: str | None,
    shard: tuple[int, int] | None,
) -> None:
    """Lint USD files and directories (recursively: .usd, .usda, .usdc, .usdz)."""
    _import_engine(read_ahead=_linted_here(paths, config_path, isolated, no_roots))
    check_stopped()  # a signal while USD imported its modules
    from .running.pipeline import Request, RequestError, run

    request = Request(
        paths,
        select=_split(select),
        ignore=_split(ignore),
        extend_select=_split(extend_select),
        fail_on=fail_on,
        config=config_path,
        isolated=isolated,
        use_roots=not no_roots,
        fix=_fix_request(fix, unsafe_fixes, show_diff, fix_to),
        variants=variants,
        max_variant_combinations=max_variant_combinations,
        baseline=baseline_file,
        write_baseline=write_baseline_file,
        jobs=jobs,
        timeout=timeout,
        full_composition=full_composition,
        profile=profile,
        cache=not no_cache,
        cache_dir=cache_dir,
        shard=shard,
        output=output_file,
    )
    try:
        outcome = run(request)
    except RequestError as exc:
        raise ToolError(str(exc)) from None
    options = FormatOptions(
        show_info=show_info,
        tool_version=__version__,
        statistics=statistics,
        fixing=request.fix is not None,
        configuration=outcome.configuration,
    )
    if show_diff:
        # stdout carries the diff alone; the report goes only to --output.
        _write(escape("".join(outcome.diffs)))
        if output_file:
            _emit_report(outcome.report, output_format, outcome.rules, options, output_file)
    else:
        _emit_report(outcome.report, output_format, outcome.rules, options, output_file)
    for note in outcome.notes:
        click.echo(f"usdrender-lint: {printable(note)}", err=True)
    for error in outcome.errors:
        _error(error)
    sys.exit(outcome.exit_status)


def _shard(value: str | None) -> tuple[int, int] | None:
    if value is None:
        return None
    from .running.shards import ShardError, parse_shard

    try:
        return parse_shard(value)
    except ShardError as exc:
        raise click.BadParameter(str(exc)) from None


@cli.command()
@click.argument("reports", nargs=-1, required=True, type=click.Path(dir_okay=False))
@_report_format_option
@click.option(
    "--fail-on",
    type=click.Choice(FAIL_ON_CHOICES),
    default=None,
    help="Lowest severity that makes the exit code 1  [default: the config's, else error].",
)
@_show_info_option
@click.option(
    "--config",
    "config_path",
    type=click.Path(dir_okay=False),
    help="Read settings (fail-on, the rules described) from this file.",
)
@_isolated_option
@_report_output_option
@_statistics_option
def merge(
    reports: tuple[str, ...],
    output_format: str,
    fail_on: str | None,
    show_info: bool,
    config_path: str | None,
    isolated: bool,
    output_file: str | None,
    statistics: bool,
) -> None:
    """Merge JSON reports (of 'check --shard K/N' jobs) into one report.

    The exit code is that of one check over all the files: 2 when a file could
    not be linted, else 1 when a finding reaches --fail-on, else 0."""
    _import_engine()
    from .running.merge import MergeError, merge_reports
    from .running.pipeline import Request, RequestError, exit_status, prepare

    try:
        report, configuration = merge_reports(reports)
        # The configuration decides fail-on and which rules a SARIF report describes.
        prepared = prepare(Request((".",), fail_on=fail_on, config=config_path, isolated=isolated))
    except (MergeError, RequestError) as exc:
        raise ToolError(str(exc)) from None
    options = FormatOptions(
        show_info=show_info,
        tool_version=__version__,
        statistics=statistics,
        fixing=bool(report.applied_fixes or report.unapplied_fixes),
        configuration=configuration,
    )
    _emit_report(report, output_format, prepared.linter.rules, options, output_file)
    for error in (r.error or r.file for r in report.errored_files):
        _error(error)
    sys.exit(exit_status(report, prepared.settings.fail_on))


def _fix_request(fix: bool, unsafe: bool, show_diff: bool, fix_to: str | None):
    """What fixing the flags ask for, or None when none was."""
    from .running.pipeline import FixRequest

    if show_diff and fix_to:
        raise ToolError("use either --diff or --fix-to, not both")
    if not (fix or show_diff or fix_to):
        if unsafe:
            raise ToolError("--unsafe-fixes needs --fix, --diff or --fix-to")
        return None
    return FixRequest(write=not show_diff, unsafe=unsafe, fix_to=fix_to)


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
        from .explain import rule_info

        report = replace(report, rules=tuple(rule_info(type(rule)) for rule in rules))
    check_stopped()
    if output_file is None:
        stdout = _Stdout()
        formatter.render(report, stdout, options)  # type: ignore[arg-type]
        stdout.flush()
        return
    import io

    buffer = io.StringIO()
    formatter.render(report, buffer, options)
    _write_file(output_file, buffer.getvalue(), "the report")


def _write_file(path: str | Path, text: str, what: str) -> None:
    """Write ``text`` to ``path`` as a shell's ``>`` would, atomically where
    that can be (atomic.write_output); a failure is one line, exit 2."""
    from .atomic import write_output

    try:
        write_output(path, text)
    except BrokenPipeError:
        raise StdoutGone from None  # a pipe the user named, whose reader left
    except OSError as exc:
        raise ToolError(f"{path}: cannot write {what}: {exc.strerror or exc}") from None


def _time_option(
    ctx: click.Context, param: click.Parameter, text: str | None
) -> tuple[float | None, bool]:
    """``--time``: (a number, False), or (None, True) for ``default``
    (Usd.TimeCode.Default()); (None, False) when not given."""
    if text is None:
        return None, False
    if text.strip().lower() == "default":
        return None, True
    try:
        value = float(text)
    except ValueError:
        raise click.BadParameter(f"{text!r} is not a number or 'default'") from None
    if value != value or value in (float("inf"), float("-inf")):
        raise click.BadParameter(f"{text!r} is not a finite time")
    return value, False


@cli.command("spec")
@click.argument("paths", nargs=-1, required=True, type=click.Path(readable=False))
@click.option("--settings", "settings_path", help="Only this RenderSettings prim (a path).")
@click.option(
    "--time",
    "time_option",
    callback=_time_option,
    help="Time to read the camera and productName at: a number or 'default'  "
    "[default: the stage's startTimeCode when authored, else Default].",
)
@click.option(
    "--format",
    "output_format",
    type=click.Choice(["text", "json", "svg"], case_sensitive=False),
    default="text",
    show_default=True,
)
@click.option(
    "--output",
    help="Write to this file (text, json; atomically) or folder (svg: one file per product).",
)
@click.option(
    "--config",
    "config_path",
    type=click.Path(dir_okay=False),
    help="Read settings (rule selection for the findings) from this file.",
)
@_isolated_option
@_profile_option
@_jobs_option
@_timeout_option
def spec_command(
    paths: tuple[str, ...],
    settings_path: str | None,
    time_option: tuple[float | None, bool],
    output_format: str,
    output: str | None,
    config_path: str | None,
    isolated: bool,
    profile: str | None,
    jobs: int | None,
    timeout: float,
) -> None:
    """Show what will render: per RenderSettings and product, the camera, image
    size, conformed aperture, data window, outputs, and the values the linter reports.

    Exit codes: 0 every file's specification was computed; 2 a file could not
    be read (missing, unopenable, timed out) or a usage error.
    """
    time, default_time = time_option
    if output_format == "svg" and output is None:
        raise ToolError("--format svg writes one file per product: give --output DIR")
    # spec reads each file on its own: no roots.
    _import_engine(read_ahead=_linted_here(paths, config_path, isolated, no_roots=True))
    from functools import partial

    from .render_spec.compute import SpecOptions, compute_file_spec
    from .render_spec.document import spec_document
    from .running.inspect import InspectedFile, InspectRequest, inspect_files
    from .running.pipeline import RequestError

    options = SpecOptions(time=time, default_time=default_time, settings=settings_path)
    request = InspectRequest(
        paths,
        config=config_path,
        isolated=isolated,
        profile=profile,
        jobs=jobs,
        timeout=timeout,
        output=output if output_format != "svg" else None,
    )
    try:
        inspection = inspect_files(request, partial(compute_file_spec, options=options))
    except RequestError as exc:
        raise ToolError(str(exc)) from None
    files = [(r, r.value if isinstance(r, InspectedFile) else None) for r in inspection.results]
    inputs = [result.file for result, _ in files]
    _emit_spec(spec_document(files, __version__), output_format.lower(), output, inputs)
    for error in inspection.errors:
        _error(error)
    sys.exit(inspection.exit_status)


def _emit_spec(
    document: dict, output_format: str, output: str | None, inputs: Sequence[str] = ()
) -> None:
    """The spec document as JSON or text, to stdout or ``output`` (atomically),
    or as one SVG per product into the folder ``output`` (listing the files).
    Names that are not UTF-8 are written in their lossless escaped form, and
    the views printed as they are escape control characters too."""
    from functools import partial

    if output_format == "json":
        document = escaped(document)
    else:
        document = escaped(document, partial(printable, limit=None))
    if output_format == "svg":
        from pathlib import Path

        from .render_spec.svg import svg_files

        folder = Path(output or ".")
        if folder.exists() and not folder.is_dir():
            raise ToolError(f"{folder}: --format svg needs a folder, and this is a file")
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ToolError(f"{folder}: cannot create the folder: {exc.strerror or exc}") from None
        from .running.outputs import OutputOnInput, refuse_inputs

        pictures = svg_files(document)
        try:
            refuse_inputs([(str(folder / name), "a picture") for name, _ in pictures], inputs)
        except OutputOnInput as exc:
            raise ToolError(str(exc)) from None
        for name, text in pictures:
            _write_file(folder / name, text, "the picture")
            _write(f"{printable(str(folder / name))}\n")
        return
    if output_format == "json":
        import json

        text = json.dumps(document, indent=2) + "\n"
    else:
        import io

        from .formatters.text import write_lines
        from .render_spec.textview import document_lines

        if output is None:
            stdout = _Stdout()
            write_lines(document_lines(document), stdout)  # type: ignore[arg-type]
            stdout.flush()
            return
        buffer = io.StringIO()  # not a terminal: plain text
        write_lines(document_lines(document), buffer)
        text = buffer.getvalue()
    if output is None:
        _write(text)
    else:
        _write_file(output, text, "the specification")


@cli.command("rules")
@click.option(
    "--format",
    "output_format",
    type=click.Choice(["text", "json"]),
    default="text",
    show_default=True,
)
@click.option(
    "--profile",
    type=click.Choice(_profile_choices()[1:]),
    default=None,
    help="Show the effective rule set under this renderer profile.",
)
def list_rules(output_format: str, profile: str | None) -> None:
    """List every registered rule (under --profile: its severity and whether it runs)."""
    registry = _registry()
    from .profiles import get_profile
    from .profiles.effective import effective_rules

    chosen = get_profile(profile) if profile else None
    rows = effective_rules(registry.rules, chosen)
    if output_format == "json":
        import json

        out = []
        for row in rows:
            item: dict[str, object] = {
                "code": row.rule.code,
                "name": row.rule.name,
                "severity": row.rule.severity.value,
                "summary": row.rule.summary(),
                "fix": row.rule.fix_safety,
                "plugin": registry.origins[row.rule.code],
            }
            if chosen is not None:
                item["profile"] = chosen.name
                item["effective_severity"] = row.severity.value if row.severity else None
                item["enabled"] = row.enabled
                item["why"] = row.why
            out.append(item)
        _write(json.dumps(out, indent=2) + "\n")
        return
    title = f"{len(registry.rules)} rules"
    if chosen is not None:
        title += f" under the {chosen.name} profile"
    lines = []
    for row in rows:
        r = row.rule
        cells = [r.code, r.name, row.severity.value if row.severity else "-", r.fix_safety]
        if chosen is not None:
            cells.append("on" if row.enabled else "off")
        cells.append(r.summary() if not row.why else f"{r.summary()} [{row.why}]")
        lines.append(tuple(cells))
    _write(rules_text(lines, _terminal_width(), title))


@cli.command("server")
def server_command() -> None:
    """Run the language server for editors (LSP over stdio; the [server] extra)."""
    from .server import main as serve

    serve()


def _terminal_width() -> int | None:
    """The terminal's width, or None when stdout is not a terminal."""
    if sys.stdout is None or not sys.stdout.isatty():
        return None
    import shutil

    return shutil.get_terminal_size().columns


def rules_text(rows: Sequence[tuple[str, ...]], width: int | None, title: str) -> str:
    """Rows of (code, name, severity, fix class, [runs,] summary), every field
    in full: one aligned line per rule; on a terminal too narrow for those
    lines, each rule is wrapped at words over a few lines instead (nothing is
    ever cut)."""
    import textwrap

    columns = len(rows[0]) - 1 if rows else 0
    widths = [max((len(row[column]) for row in rows), default=0) for column in range(columns)]
    lines = [title]
    aligned = [
        "  ".join(field.ljust(size) for field, size in zip(row[:-1], widths, strict=True))
        + f"  {row[-1]}"
        for row in rows
    ]
    if width is None or max(map(len, aligned), default=0) <= width:
        return "\n".join(lines + aligned) + "\n"
    # Names are kebab-case: break at spaces only, and never inside a word.
    wrap = textwrap.TextWrapper(width, break_long_words=False, break_on_hyphens=False)
    indent = "    "
    for code, name, severity, fix, *runs, summary in rows:
        wrap.initial_indent, wrap.subsequent_indent = "", indent
        ran = f", runs: {runs[0]}" if runs else ""
        lines += wrap.wrap(f"{code} {name} ({severity}, fix: {fix}{ran})")
        wrap.initial_indent = indent
        lines += wrap.wrap(summary)
    return "\n".join(lines) + "\n"


@cli.command()
@click.argument("rule")
def explain(rule: str) -> None:
    """Print a rule's documentation (by code or name)."""
    from .model import INTERNAL_ERROR_RULE as internal

    found = _registry().find(rule)
    if found is not None:
        from .explain import explain_text

        _write(explain_text(found))
    elif rule.upper() == internal.code or rule.lower() == internal.name:
        header = f"{internal.code} {internal.name} ({internal.severity.value}, fix: {internal.fix})"
        _write(f"{header}\n\n{internal.doc}\n")
    else:
        raise ToolError(f"no rule has the code or name {rule!r} (see 'usdrender-lint rules')")


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
    _write(f"{folder}\n")
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
    """Console entry point: no traceback ever reaches the user. Ctrl-C exits
    130 and SIGTERM 143 (128 + the signal) after cleaning up; a closed or
    broken stdout exits 2 quietly."""
    _open_closed_standard_streams()
    try:
        with stop_on_signals():
            cli.main(args=argv, prog_name="usdrender-lint", standalone_mode=True)
    except SystemExit:
        raise
    except Stopped as stopped:
        click.echo(f"usdrender-lint: {stopped.reason}", err=True)
        sys.exit(stopped.exit_status)
    except StdoutGone:
        _silence_stdout()
        sys.exit(EXIT_TOOL_ERROR)
    except OSError as exc:
        if not _raised_by_echo(exc):
            _internal_error(exc)
        # click printing help, the version or usage: stdout is full or gone.
        _silence_stdout()
        if not isinstance(exc, BrokenPipeError):
            _error(f"cannot write the output: {exc.strerror or exc}")
        sys.exit(EXIT_TOOL_ERROR)
    except Exception as exc:
        _internal_error(exc)


def _raised_by_echo(exc: BaseException) -> bool:
    """Whether ``exc`` came out of ``click.echo`` (help, version, usage)."""
    import traceback

    return any(
        frame.name == "echo" and frame.filename.endswith(os.path.join("click", "utils.py"))
        for frame in traceback.extract_tb(exc.__traceback__)
    )


def _internal_error(exc: Exception) -> None:
    if os.environ.get("USDRENDER_LINT_DEBUG"):
        raise exc
    click.echo(
        f"usdrender-lint: internal error: {type(exc).__name__}: {printable(str(exc))} "
        "(set USDRENDER_LINT_DEBUG=1 for a traceback)",
        err=True,
    )
    sys.exit(EXIT_TOOL_ERROR)


def _open_closed_standard_streams() -> None:
    """Put /dev/null on a standard file descriptor that was closed when the
    command started (``check >&-``): else the next file opened would get the
    number, and whatever USD prints would land in it. Python already made
    sys.stdout None for it, which the report's writing treats as gone."""
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            null = os.open(os.devnull, os.O_RDWR)
            if null != fd:
                os.dup2(null, fd)
                os.close(null)


def _silence_stdout() -> None:
    """Point fd 1 at /dev/null, so that flushing stdout at exit fails no more."""
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    os.close(null)


def _linted_here(
    paths: Sequence[str], config_path: str | None, isolated: bool, no_roots: bool
) -> str | None:
    """The file the supervised child will lint in its own process, if any: a
    lone layer file not linted inside the stage roots a configuration names
    (the roots' layers are found in worker processes)."""
    if not supervisor.supervised or len(paths) != 1 or not _read_ahead.wanted(paths[0]):
        return None
    if not no_roots:
        try:
            roots = load_settings(config_path, isolated=isolated, start=paths[0]).roots
        except (ConfigError, OSError):
            return None  # the run says what is wrong
        if roots:
            return None
    return paths[0]


def _import_engine(read_ahead: str | None = None) -> None:
    """Import USD and the engine with the cyclic garbage collector paused, then
    freeze what the imports made. Imports make no garbage worth collecting, and
    each collection on the way would walk every object USD created so far
    (about 10 ms of a one-file check); frozen objects are never walked again.
    Called by the commands that need USD: ``--help`` and ``--version`` do not.
    ``read_ahead``: a file whose layers are read on a thread meanwhile, under
    the supervised child's memory cap (running/read_ahead.py)."""
    if "usdrender_lint.running.pipeline" in sys.modules:
        return
    from .running.interrupts import deferred

    enabled = gc.isenabled()
    gc.disable()
    try:
        with deferred():  # a Ctrl-C arrives after the imports, not inside USD's
            if read_ahead is not None:
                limit_supervised_memory()
                _read_ahead.start(read_ahead)
            from .running import pipeline  # noqa: F401 - USD, the engine and the rule API
    finally:
        gc.freeze()
        if enabled:
            gc.enable()
