"""``usdrender-lint rules``: every registered rule, as ``check`` run here would
run it (the configuration's selection and severities), under a renderer profile."""

from __future__ import annotations

import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, TextIO

import click

from ..records import record
from .loading import registry as load_registry
from .options import (
    config_option,
    isolated_option,
    profile_choices,
    setting_options,
    setting_values,
)
from .output import ToolError, note
from .views import emit, format_option, view

if TYPE_CHECKING:
    from ..profiles.effective import EffectiveRule
    from ..profiles.model import Profile
    from ..registry import Registry


@record(frozen=True)
class RuleTable:
    """What the views show: the rows, where each rule comes from, the profile."""

    rows: Sequence[EffectiveRule]
    registry: Registry
    profile: Profile | None
    #: A configuration file or a flag chose the rows: each says whether it runs.
    configured: bool = False

    @property
    def effective(self) -> bool:
        return self.profile is not None or self.configured


@view("rules", "text")
def _text(table: RuleTable, stream: TextIO) -> None:
    title = f"{len(table.registry.rules)} rules"
    if table.profile is not None:
        title += f" under the {table.profile.name} profile"
    if table.configured:
        title += f", {sum(row.enabled for row in table.rows)} of them run as configured"
    lines = []
    for row in table.rows:
        r = row.rule
        cells = [r.code, r.name, row.severity.value if row.severity else "-", r.fix_safety]
        if table.effective:
            cells.append("on" if row.enabled else "off")
        cells.append(r.summary() if not row.why else f"{r.summary()} [{row.why}]")
        lines.append(tuple(cells))
    stream.write(rules_text(lines, _terminal_width(stream), title))


@view("rules", "json")
def _json(table: RuleTable, stream: TextIO) -> None:
    import json

    out = []
    for row in table.rows:
        item: dict[str, object] = {
            "code": row.rule.code,
            "name": row.rule.name,
            "severity": row.rule.severity.value,
            "summary": row.rule.summary(),
            "fix": row.rule.fix_safety,
            "plugin": table.registry.origins[row.rule.code],
        }
        if table.profile is not None:
            item["profile"] = table.profile.name
        if table.effective:
            item["effective_severity"] = row.severity.value if row.severity else None
            item["enabled"] = row.enabled
            item["why"] = row.why
        out.append(item)
    stream.write(json.dumps(out, indent=2) + "\n")


@click.command("rules")
@format_option("rules")
@click.option(
    "--profile",
    type=click.Choice(profile_choices()[1:]),
    default=None,
    help="Show the effective rule set under this renderer profile (default: the "
    "configuration's profile, unless it is auto).",
)
@setting_options("rules")
@config_option("Read settings from this file instead of the nearest one.")
@isolated_option
def list_rules(
    output_format: str,
    profile: str | None,
    config: tuple[str | None, tuple[str, ...]],
    isolated: bool,
    **settings: Any,
) -> None:
    """List every registered rule. With a configuration (the one check finds
    from the working directory, or --config) or selection flags, each rule
    says whether check runs it and at what severity; under --profile (or the
    configuration's profile), as that renderer's profile treats it."""
    registry = load_registry()
    from ..running.pipeline import Request, RequestError
    from ..running.rule_listing import configured_rules

    request = Request(
        (".",),
        config=config[0],
        config_overrides=config[1],
        isolated=isolated,
        profile=profile,
        **setting_values("rules", settings),
    )
    try:
        listed = configured_rules(registry, request)
    except RequestError as exc:
        raise ToolError(str(exc)) from None
    for line in listed.notes:
        note(line)
    table = RuleTable(listed.rows, registry, listed.profile, listed.configured)
    emit("rules", output_format, table, what="the rule list")


def _terminal_width(stream: TextIO) -> int | None:
    """The terminal's width, or None when the output is not a terminal."""
    if sys.stdout is None or not stream.isatty():
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
