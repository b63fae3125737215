"""``usdrender-lint check``: lint files and report (the pipeline does the work)."""

from __future__ import annotations

import re
import sys
from collections.abc import Callable, Sequence
from dataclasses import replace
from functools import partial
from typing import TYPE_CHECKING, Any, NoReturn

import click

from .. import __version__
from ..formatters import FormatOptions, load_formatter, reads_configuration, reads_rules
from ..paths import display_path, escape, tidy
from ..records import record
from ..running.interrupts import check_stopped
from .loading import import_engine, registry, supervision
from .options import (
    checked_formatters,
    config_option,
    isolated_option,
    report_format_option,
    report_output_option,
    setting_options,
    setting_values,
    show_info_option,
    statistics_option,
)
from .output import ToolError, errors_after_report, note, stdout_to_stderr, write
from .views import send

if TYPE_CHECKING:
    from ..api import Rule
    from ..model import Finding, Report, RuleInfo
    from ..running.pipeline import Outcome, Request
    from ..running.standard_input import StandardInput


#: The names pre-commit hands the hooks (.pre-commit-hooks.yaml's ``files``).
#: (Pattern text: re compiles it at first use, not at every start-up.)
_HOOK_FILES = r"(?i)\.usd[acz]?$"
#: The hooks' entry says so: the command is run by pre-commit.
PRE_COMMIT_FLAG = "--pre-commit"


class _Check(click.Command):
    """``check``; run by the pre-commit hooks (PRE_COMMIT_FLAG), a staged file
    whose name starts with ``-`` is a path, not an option."""

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        if PRE_COMMIT_FLAG in args[: args.index("--") if "--" in args else None]:
            args = staged_files_as_paths(args)
        return super().parse_args(ctx, args)


def staged_files_as_paths(args: list[str]) -> list[str]:
    """pre-commit runs the hook's entry, the user's ``args``, then the staged
    files, with no ``--`` between (it adds none, and one in the entry or the
    args would make the user's args paths): a file named ``-x.usda`` would be
    read as options. The files are the words at the end that name existing USD
    files; those that start with ``-`` are written ``./-x.usda``, the same file
    (every report names it ``-x.usda``). A user's option value such as
    ``--fix-to -o.usda`` may be rewritten too: it names the same file."""
    import os

    args = list(args)
    at = len(args)
    while at > 0 and re.search(_HOOK_FILES, args[at - 1]) and os.path.lexists(args[at - 1]):
        at -= 1
        if args[at].startswith("-"):
            args[at] = os.path.join(os.curdir, args[at])
    return args


@click.command(cls=_Check)
# readable=False: an unreadable file is reported by the engine, and the others
# are still linted, instead of click refusing the whole command.
@click.argument("paths", nargs=-1, type=click.Path(readable=False))
@report_format_option()
@setting_options("check")
@show_info_option
@config_option("Read settings from this file instead of the nearest one.")
@isolated_option
@click.option(
    "--no-roots",
    is_flag=True,
    help="Lint PATHS on their own, not inside the stage roots the config names.",
)
@report_output_option
@statistics_option
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
@click.option(
    "--fix",
    is_flag=True,
    help="Apply the safe fixes, then report what remains (with '-': print the fixed text).",
)
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
    "--exit-non-zero-on-fix",
    is_flag=True,
    help="With --fix: exit 1 when a fix was applied, even if no finding at or above "
    "--fail-on remains (as ruff's).",
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
    "--stdin-filename",
    metavar="PATH",
    help="With '-' or no path (a text layer on standard input): the path it stands for, which "
    "resolves its relative asset paths, finds its configuration and names it in the report.",
)
@click.option(
    "--shard",
    metavar="K/N",
    callback=lambda _ctx, _param, value: _shard(value),
    help="Lint only part K of N of the files (a CI matrix job); see 'merge'.",
)
@click.option(
    "--watch",
    is_flag=True,
    help="Check again whenever a layer, configuration or .gitignore below PATHS changes, "
    "until Ctrl-C (the [watch] extra).",
)
@click.option(
    "-q",
    "--quiet",
    is_flag=True,
    help="Print the findings and nothing else: no summary line, no fixes applied, no "
    "notes or progress bar on stderr (a file that could not be linted is still said).",
)
@click.option(
    "-s",
    "--silent",
    is_flag=True,
    help="Print no report (the exit code says it; --output still writes one) and, as "
    "--quiet, no notes; a file that could not be linted is still said on stderr.",
)
@click.option(
    PRE_COMMIT_FLAG,
    "pre_commit",
    is_flag=True,
    hidden=True,
    help="Run by the pre-commit hooks: the staged files that end the arguments are paths, "
    "even when a name starts with '-'.",
)
@click.option(
    "--show-files",
    is_flag=True,
    help="Print the files a check would lint, one a line, and exit 0: nothing is linted.",
)
@click.option(
    "--show-settings",
    is_flag=True,
    help="Print the settings a check would lint with (as a configuration file's TOML, "
    "each key's origin in a comment) and the rules that run, and exit 0.",
)
def check(
    paths: tuple[str, ...],
    output_format: str,
    show_info: bool,
    config: tuple[str | None, tuple[str, ...]],
    isolated: bool,
    no_roots: bool,
    output_file: str | None,
    statistics: bool,
    baseline_file: str | None,
    write_baseline_file: str | None,
    fix: bool,
    unsafe_fixes: bool,
    show_diff: bool,
    exit_non_zero_on_fix: bool,
    fix_to: str | None,
    fix_drop_comments: bool,  # no effect (see its help)
    shard: tuple[int, int] | None,
    stdin_filename: str | None,
    watch: bool,
    quiet: bool,
    silent: bool,
    show_files: bool,
    show_settings: bool,
    pre_commit: bool,  # read by _Check as it parses
    **settings: Any,
) -> None:
    """Lint USD files and directories (recursively: .usd, .usda, .usdc, .usdz;
    default: the working directory); '-' lints one text layer read from
    standard input (see --stdin-filename).

    Exit codes: 0 no finding at or above --fail-on; 1 findings at or above it;
    2 the tool could not do its job (bad usage or configuration, a file it could
    not lint).
    """
    import_engine()
    check_stopped()  # a signal while USD imported its modules
    from ..running.pipeline import Request

    stdin = _standard_input(paths, stdin_filename)
    # No path: the working directory, as ruff checks it and as clean cleans it.
    paths = paths or (".",)
    if stdin is not None and output_format in ("html", "full"):
        # Their source lines (and html's fix diffs and pictures) are read from the files on disk.
        raise ToolError(
            f"'-' (a layer on standard input) cannot be combined with --format {output_format}, "
            "which reads the linted files from disk: save the text and give its path"
        )
    request = Request(
        paths if stdin is None else (stdin.name,),
        stdin=stdin,
        config=config[0],
        config_overrides=config[1],
        isolated=isolated,
        use_roots=not no_roots,
        fix=_fix_request(fix, unsafe_fixes, show_diff, fix_to),
        baseline=baseline_file,
        write_baseline=write_baseline_file,
        shard=shard,
        output=output_file,
        supervision=supervision(),
        progress=False if quiet or silent else None,
        **setting_values("check", settings),
    )
    if show_files or show_settings:
        _show(request, show_files, show_settings)
    shown = _Shown(output_format, show_info, statistics, show_diff, quiet or silent, silent)
    check_once = partial(_check_once, request, shown)
    if watch:
        _watch(request, check_once)
    outcome = check_once()
    fixed = exit_non_zero_on_fix and bool(outcome.report.applied_fixes)
    sys.exit(max(outcome.exit_status, 1) if fixed else outcome.exit_status)


@record(frozen=True)
class _Shown:
    """What a check prints besides the findings' data (its report options)."""

    output_format: str
    show_info: bool
    statistics: bool
    show_diff: bool
    #: --quiet (or --silent): no summary, applied fixes or notes.
    quiet: bool
    #: --silent: no report either, unless --output names where it goes.
    silent: bool


def _check_once(request: Request, shown: _Shown) -> Outcome:
    """One check: lint, write the report and the notes; the outcome."""
    from ..running.pipeline import RequestError, run

    try:
        with stdout_to_stderr():
            outcome = run(request)
    except RequestError as exc:
        raise ToolError(str(exc)) from None
    options = FormatOptions(
        # A gate that fails on info findings shows them: they are why it fails.
        show_info=shown.show_info or outcome.fails_on_info,
        tool_version=__version__,
        statistics=shown.statistics,
        quiet=shown.quiet,
        fixing=request.fix is not None,
        dry_run=shown.show_diff,
        shard=request.shard,
        settings_of=outcome.settings_by_file().get,
    )
    report, rules, output_format = outcome.report, outcome.rules, shown.output_format
    output_file = request.output
    if shown.show_diff or outcome.text is not None:
        # stdout carries the diff, or the fixed text of check --fix -, alone (data that
        # was asked for, printed even --silent); the report goes only to --output.
        if outcome.text is not None:
            write(outcome.text, encoding="utf-8")  # a text layer's own encoding
        else:
            write(escape("".join(outcome.diffs)))
        if output_file:
            emit_report(report, output_format, rules, options, output_file, outcome.configuration)
    elif output_file or not shown.silent:
        emit_report(report, output_format, rules, options, output_file, outcome.configuration)
    if not shown.quiet:
        for line in outcome.notes:
            note(line)
    # --silent showed no report that said them: on stderr, wherever it goes.
    shown_by_report = not shown.silent or output_file is not None
    errors_after_report(outcome.errors, output_format, output_file, shown_by_report)
    return outcome


def _watch(request: Request, check_once: Callable[[], Outcome]) -> NoReturn:
    """--watch: check, then check again after each relevant change, until a
    signal stops the command (exit 130 for Ctrl-C). A round that cannot run
    (a configuration saved half-written) says why in one line and waits."""
    import time

    from ..entrypoints import read_once
    from ..running.watching import Watcher, WatchUnavailable

    _refuse_watch(request)
    try:
        watcher = Watcher(request.paths)
    except WatchUnavailable as exc:
        raise ToolError(str(exc)) from None
    polled = {p for p in (request.config, request.baseline) if isinstance(p, str)}
    changed: list[str] = []
    while True:
        if sys.stdout.isatty() and request.output is None:
            click.clear()
        if changed:
            shown = ", ".join(display_path(p) for p in changed[:3])
            more = f" and {len(changed) - 3} more" if len(changed) > 3 else ""
            note(f"{time.strftime('%H:%M:%S')} changed: {shown}{more}")
        try:
            with read_once():  # a rule plugin installed since the last round is found
                outcome = check_once()
            polled |= {s for o in outcome.parts or (outcome,) for s in o.settings.sources}
        except ToolError as exc:
            exc.show()
        polled |= _nearest_configuration(request) | _gitignores_above(request)
        watcher.poll(polled | _layers_of_files_given(request))
        note(f"{time.strftime('%H:%M:%S')} watching for changes (Ctrl-C stops)")
        changed = watcher.wait()


def _nearest_configuration(request: Request) -> set[str]:
    """The files a search from each path given finds its configuration among,
    for --watch to poll: every configuration file name in each folder from the
    path's up to the one that holds its configuration (all of them without one),
    so that a configuration saved half-written, or a new one saved nearer than
    the one in effect, starts a round. Without one, the user's own too."""
    from ..config import (
        CONFIG_FILE_NAMES,
        ConfigError,
        config_file_in,
        search_start,
        user_config_dir,
    )

    if request.isolated or request.config is not None:
        return set()
    polled: set[str] = set()
    for path in request.paths:
        here = search_start(path)
        for folder in (here, *here.parents):
            polled.update(str(folder / name) for name in CONFIG_FILE_NAMES)
            try:
                if config_file_in(folder) is not None:
                    break
            except ConfigError:
                break  # the round said why
        else:  # no project configuration: the user's own is read (config.fallback_settings)
            user = user_config_dir()
            polled.update(str(user / name) for name in CONFIG_FILE_NAMES if user is not None)
    return polled


def _layers_of_files_given(request: Request) -> set[str]:
    """The layers each file given composes (its sublayers, references,
    payloads, clips), and those it names that are missing, for --watch to poll:
    the events are heard for the file itself only, and a save of a sublayer
    beside it (or of a missing one) changes the stage's report. Read again each
    round: a save can add or drop a sublayer."""
    import os

    from ..running.roots import dependencies

    return {
        layer
        for path in request.paths
        if os.path.isfile(path)
        for layer in dependencies(path, missing=True)
    }


def _gitignores_above(request: Request) -> set[str]:
    """The ignore files above the paths given that a walk reads (those of their
    parents up to the repository's root), for --watch to poll: the events are
    heard below the paths only."""
    import os

    from ..running.discovery import git_exclude, repository_chain
    from ..running.watching import GITIGNORE

    polled: set[str] = set()
    for path in request.paths:
        top = os.path.abspath(path if os.path.isdir(path) else os.path.dirname(path) or ".")
        chain, root = repository_chain(top)
        if root is not None:  # outside a repository, only the walked folders' own count
            polled.update([*(os.path.join(f, GITIGNORE) for f in chain), git_exclude(root)])
    return polled


def _refuse_watch(request: Request) -> None:
    """A watched check writes nothing but its report: fixes would write the files
    it watches, and a baseline is written once."""
    for flag, given in (
        ("'-' (standard input)", request.stdin is not None),
        ("--fix, --diff or --fix-to", request.fix is not None),
        ("--write-baseline", request.write_baseline is not None),
    ):
        if given:
            raise ToolError(
                f"--watch cannot be combined with {flag}: it writes nothing but its report"
            )


def _show(request: Request, files: bool, settings: bool) -> None:
    """--show-files, --show-settings: print what a check would do, then exit 0."""
    from ..running.pipeline import RequestError
    from ..running.show import planned_files, settings_text

    try:
        if settings:
            write(escape(settings_text(request)))
        if files:
            planned, notes = planned_files(request)
            write("".join(escape(path) + "\n" for path in planned))
            for line in notes:
                note(line)
    except RequestError as exc:
        raise ToolError(str(exc)) from None
    sys.exit(0)


def _standard_input(paths: tuple[str, ...], name: str | None) -> StandardInput | None:
    """``check -`` or, as ruff reads it, ``check --stdin-filename NAME`` with no
    path: the text on standard input (read by the supervisor before its fork,
    when it supervises), as the layer ``name`` stands for."""
    if "-" not in paths:  # standard_input.STDIN, not imported by a check of files
        if name is None:
            return None
        if paths:
            # ruff lints standard input instead, with a warning: a gate would pass on
            # a text nobody meant to lint.
            raise ToolError(
                "--stdin-filename names the layer read from standard input: give '-' "
                f"or no path, not {', '.join(map(repr, paths[:3]))}"
            )
    from ..running.standard_input import STDIN, StandardInputError, decode

    how = "-" if paths else f"--stdin-filename {name}"

    if len(paths) > 1:
        raise ToolError("'-' (a layer on standard input) is linted alone: give no other paths")
    given = supervision()
    data = given.stdin if given is not None else None
    if data is None:
        if sys.stdin is None or sys.stdin.isatty():
            raise ToolError(
                f"'{how}' reads a text layer from standard input, which is a terminal: pipe one "
                f"in (usdrender-lint check {how} < shot.usda)"
            )
        data = sys.stdin.buffer.read()
    # Named as check names the file itself: ./shots//a.usda is shots/a.usda.
    name = tidy(name) if name is not None else None
    try:
        return decode(data, name or STDIN)
    except StandardInputError as exc:
        raise ToolError(f"{name or STDIN}: {exc}") from None


def _shard(value: str | None) -> tuple[int, int] | None:
    if value is None:
        return None
    from ..running.shards import ShardError, parse_shard

    try:
        return parse_shard(value)
    except ShardError as exc:
        raise click.BadParameter(str(exc)) from None


def _fix_request(fix: bool, unsafe: bool, show_diff: bool, fix_to: str | None):
    """What fixing the flags ask for, or None when none was."""
    from ..running.pipeline import FixRequest

    if show_diff and fix_to:
        raise ToolError("use either --diff or --fix-to, not both")
    if not (fix or show_diff or fix_to):
        if unsafe:
            raise ToolError("--unsafe-fixes needs --fix, --diff or --fix-to")
        return None
    return FixRequest(write=not show_diff, unsafe=unsafe, fix_to=fix_to)


def emit_report(
    report: Report,
    output_format: str,
    rules: Sequence[Rule],
    options: FormatOptions,
    output_file: str | None,
    configuration: Callable[[], str] | None = None,
) -> None:
    """Render with the registered formatter, to stdout or ``output_file``.
    ``rules`` (the rules that ran) are described in the report only for a
    formatter that reads them: building that costs every rule's docstring.
    ``configuration`` computes the run's digest, also only for a formatter
    that reads it (into ``options.configuration``)."""
    formatter = load_formatter(output_format, checked_formatters())
    if reads_rules(formatter):
        report = replace(report, rules=_described(report, rules))
    if configuration is not None and reads_configuration(formatter):
        options = replace(options, configuration=configuration())
    check_stopped()
    report = _relative_messages(report)
    send(lambda stream: formatter.render(report, stream, options), output_file, "the report")


def _described(report: Report, rules: Sequence[Rule]) -> tuple[RuleInfo, ...]:
    """The rules that ran, and each registered rule a finding's code names
    that did not (ST001, which every run reports): a SARIF report describes
    each result's rule with its documentation."""
    from ..explain import rule_info

    infos = {rule.code: rule_info(type(rule)) for rule in rules}
    missing = sorted({finding.code for finding in report.findings} - set(infos))
    if missing:
        known = registry()
        for code in missing:
            if (found := known.find(code)) is not None:
                infos[code] = rule_info(found)
    return tuple(infos.values())


def _relative_messages(report: Report) -> Report:
    """The report with the absolute paths in its messages written relative to
    the working directory when below it, as its files are named."""
    from ..paths import relative_in

    files = []
    renamed: dict[Finding, Finding] = {}
    for result in report.files:
        findings = tuple(replace(f, message=relative_in(f.message)) for f in result.findings)
        renamed.update(
            (old, new) for old, new in zip(result.findings, findings, strict=True) if old != new
        )
        files.append(result if findings == result.findings else replace(result, findings=findings))
    # The findings the baseline holds back are the report's own: the same once renamed.
    held = frozenset(renamed.get(f, f) for f in report.baseline_held)
    return replace(report, files=tuple(files), baseline_held=held)
