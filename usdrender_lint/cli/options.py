"""The commands' options. Those of a setting are made from the settings
table (:mod:`usdrender_lint.settings_table`): its flag, help, default and the
table's own check of a value, so a flag and a configuration key can never
read a value differently."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import click

from ..settings_table import ConfigError, Setting, flag_settings

if TYPE_CHECKING:
    from click.shell_completion import CompletionItem

    from ..entrypoints import EntryPointLike

#: Flags of kind "int"/"float": a value checked by the setting's own parser.
_NUMBERS: dict[str, click.ParamType] = {"int": click.INT, "float": click.FLOAT}


class _Checked(click.ParamType):
    """A number checked by the settings table's parser: a value out of range
    is a usage error, exit 2."""

    def __init__(self, base: click.ParamType, parse: Callable[[Any, str], Any]) -> None:
        self.base = base
        self.parse = parse
        self.name = base.name

    def convert(self, value, param, ctx):
        number = self.base.convert(value, param, ctx)
        try:
            return self.parse(number, "it")
        except ConfigError as exc:
            self.fail(str(exc), param, ctx)


def profile_choices() -> list[str]:
    from ..profiles import AUTO, profile_names  # data only: no USD import

    return [AUTO, *profile_names()]


def _help(entry: Setting) -> str:
    if entry.shown_default is None:
        return entry.help
    return f"{entry.help}  [default: {entry.shown_default}]."


def setting_option(entry: Setting):
    """The click option of one setting; its value reaches the command under
    the setting's name (None when not given, but for off-flags and for flags
    no configuration sets)."""
    assert entry.flag is not None and entry.kind is not None
    common: dict[str, Any] = {"help": _help(entry), "hidden": entry.hidden}
    if entry.envvar:
        # Shown in --help, and named in an error about its value.
        common.update(envvar=entry.envvar, show_envvar=True)
    kind = entry.kind
    if kind == "tokens":
        if entry.name in RULE_SELECTIONS:
            common.update(shell_complete=complete_rules, callback=_no_blank_selector)
        return click.option(entry.flag, entry.name, multiple=True, **common)
    if kind == "choice":
        return click.option(entry.flag, entry.name, type=click.Choice(entry.choices), **common)
    if kind == "profile":
        return click.option(entry.flag, entry.name, type=click.Choice(profile_choices()), **common)
    if kind in _NUMBERS:
        kind_type = _Checked(_NUMBERS[kind], entry.parse)
        if entry.shown_default is None and entry.default is not None:
            common.update(default=entry.default, show_default=True)
        flags = (entry.flag, entry.short) if entry.short else (entry.flag,)
        return click.option(*flags, entry.name, type=kind_type, **common)
    if kind == "flag":
        # Not given: None lets the configuration decide; a flag no configuration
        # sets (--full-composition) is simply off.
        default = None if entry.config_key else entry.default
        flag = f"{entry.flag}/--no-{entry.flag[2:]}" if entry.negatable else entry.flag
        return click.option(flag, entry.name, is_flag=True, default=default, **common)
    if kind == "off-flag":
        # --no-cache: the setting is on unless the flag is given.
        return click.option(entry.flag, f"no_{entry.name}", is_flag=True, **common)
    if kind == "folder":
        return click.option(entry.flag, entry.name, type=click.Path(file_okay=False), **common)
    raise AssertionError(f"unknown setting kind {kind!r}")


#: The settings whose flags take rule selectors (codes, prefixes, names).
RULE_SELECTIONS = ("select", "ignore", "extend_select")


def _no_blank_selector(
    ctx: click.Context, param: click.Parameter, values: tuple[str, ...]
) -> tuple[str, ...]:
    """``--select ""`` (an unset shell variable) selected no rule at all and
    passed silently; ruff refuses an empty selector."""
    if any(not value.strip(" ,\t") for value in values):
        raise click.BadParameter("a blank value names no rule (ALL names every rule)")
    return values


def complete_rules(
    ctx: click.Context, param: click.Parameter, incomplete: str
) -> list[CompletionItem]:
    """Shell completion of a rule selector: codes (with the rule's name), names,
    families and ALL, after the commas of a list already typed."""
    # Imported here: only completion needs it (0.4 ms of every check's start-up).
    from click.shell_completion import CompletionItem

    done, _, word = incomplete.rpartition(",")
    lead = f"{done}," if done else ""
    return [
        CompletionItem(lead + value, help=help)
        for value, help in _rule_words(families=True).items()
        if value.lower().startswith(word.lower())
    ]


def complete_rule(
    ctx: click.Context, param: click.Parameter, incomplete: str
) -> list[CompletionItem]:
    """Shell completion of one rule: its code or its name."""
    from click.shell_completion import CompletionItem

    return [
        CompletionItem(value, help=help)
        for value, help in _rule_words(families=False).items()
        if value.lower().startswith(incomplete.lower())
    ]


def _rule_words(families: bool) -> dict[str, str]:
    """Each word that names rules, with what it names; none when the rules
    cannot be loaded (completion says nothing rather than fail)."""
    from .loading import registry

    try:
        rules = registry().rules
    except Exception:  # noqa: BLE001 - a broken plugin: its error is check's to say
        return {}
    words = {"ALL": "every rule"} if families else {}
    if families:
        words.update({rule.code[:2]: f"the {rule.code[:2]} rules" for rule in rules})
    for rule in rules:
        words[rule.code] = rule.name
        words[rule.name] = rule.code
    return words


def setting_options(command: str):
    """Decorate ``command`` with the options of every setting it takes."""

    def decorate(function):
        for entry in reversed(flag_settings(command)):
            function = setting_option(entry)(function)
        return function

    return decorate


def setting_values(command: str, given: dict[str, Any]) -> dict[str, Any]:
    """The values of ``command``'s setting flags, as a Request takes them:
    repeatable rule lists joined and split at commas; not given, what
    setting_option made of it (mostly None: the configuration decides)."""
    values: dict[str, Any] = {}
    for entry in flag_settings(command):
        if entry.kind == "off-flag":
            values[entry.name] = not given.pop(f"no_{entry.name}")
            continue
        value = given.pop(entry.name)
        values[entry.name] = split(value) if entry.kind == "tokens" else value
    return values


def split(values: Sequence[str]) -> tuple[str, ...] | None:
    """``--select A,B --select C`` -> ("A", "B", "C"); None when not given. A
    comma inside braces is a pattern's (``--extend-exclude '{legacy,old}/'``)."""
    if not values:
        return None
    return tuple(v.strip() for value in values for v in _outside_braces(value) if v.strip())


def _outside_braces(value: str) -> list[str]:
    """``value`` split at the commas outside ``{...}``."""
    if "{" not in value:
        return value.split(",")
    parts, depth, start = [], 0, 0
    for index, char in enumerate(value):
        if char == "{":
            depth += 1
        elif char == "}" and depth:
            depth -= 1
        elif char == "," and not depth:
            parts.append(value[start:index])
            start = index + 1
    return [*parts, value[start:]]


# Options that are not settings (what to read and where to write), shared so
# that the commands read and check them alike.
show_info_option = click.option(
    "--show-info",
    is_flag=True,
    help="Show info findings in the text, full, sarif, github, gitlab and junit reports "
    "(the json and html reports always hold them).",
)
isolated_option = click.option("--isolated", is_flag=True, help="Ignore every configuration file.")


def dash_is_stdout(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
    """``--output -``: standard output, as ``-`` is for the paths (not a file named -)."""
    return None if value == "-" else value


report_output_option = click.option(
    "--output",
    "output_file",
    type=click.Path(dir_okay=False),
    callback=dash_is_stdout,
    help="Write the report to this file instead of stdout ('-': stdout): a file is replaced "
    "atomically, keeping its owner and mode; /dev/stdout, a pipe, a FIFO or a terminal is "
    "streamed into.",
)
statistics_option = click.option(
    "--statistics", is_flag=True, help="Add counts per rule code after the report."
)


def config_option(help: str):
    """``--config FILE`` and, as ruff's, ``--config 'KEY = VALUE'`` (repeatable): the
    command gets (the file or None, the inline settings in order)."""
    return click.option(
        "--config",
        "config",
        type=click.Path(dir_okay=False),
        multiple=True,
        callback=lambda _ctx, _param, values: _file_and_inline(values),
        help=help + " Or a setting, as TOML: --config 'severity.SE003 = \"info\"' "
        "(repeatable; over the file's, under the flags).",
    )


def _file_and_inline(values: tuple[str, ...]) -> tuple[str | None, tuple[str, ...]]:
    from ..config import is_inline

    files = [value for value in values if not is_inline(value)]
    if len(files) > 1:
        raise click.BadParameter(f"one configuration file, not {len(files)}: {', '.join(files)}")
    return (files[0] if files else None), tuple(v for v in values if is_inline(v))


class FormatChoice(click.Choice):
    """The registered formatters' names, looked up the first time click needs
    them (to convert --format or its default, or to print help), not when a
    command is defined: each lookup reads every installed distribution's entry
    points, and a ``check`` should not pay for ``merge``'s option too."""

    def __init__(self) -> None:
        # Not click.Choice's __init__, which takes the names now.
        self.case_sensitive = False

    @property
    def choices(self) -> tuple[str, ...]:  # type: ignore[override]
        return tuple(sorted(self.formatters()) or ["text", "json"])

    def formatters(self) -> Mapping[str, EntryPointLike]:
        """The registered formatters, looked up once per command line run (kept
        in click's context, which a later run in the same process does not
        share): the report is written with the one --format named."""
        ctx = click.get_current_context(silent=True)
        found = ctx.meta.get(_FORMATTERS) if ctx is not None else None
        if found is None:
            from ..formatters import available_formatters

            found = available_formatters()
            if ctx is not None:
                ctx.meta[_FORMATTERS] = found
        return found


#: Where FormatChoice keeps the formatters it looked up (click's ``Context.meta``).
_FORMATTERS = "usdrender_lint.formatters"


def checked_formatters() -> Mapping[str, EntryPointLike] | None:
    """The formatters the running command's --format was checked against
    (cli/check.py's emit_report loads its formatter from them); None when none was."""
    ctx = click.get_current_context(silent=True)
    return ctx.meta.get(_FORMATTERS) if ctx is not None else None


def report_format_option():
    return click.option(
        "--format",
        "output_format",
        default="text",
        show_default=True,
        type=FormatChoice(),
        help="Report format.",
    )
