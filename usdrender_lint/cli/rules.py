"""``usdrender-lint rules``: every registered rule, or the effective set under
a renderer profile."""

from __future__ import annotations

import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING, TextIO

import click

from ..records import record
from .loading import registry as load_registry
from .options import profile_choices
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


@view("rules", "text")
def _text(table: RuleTable, stream: TextIO) -> None:
    title = f"{len(table.registry.rules)} rules"
    if table.profile is not None:
        title += f" under the {table.profile.name} profile"
    lines = []
    for row in table.rows:
        r = row.rule
        cells = [r.code, r.name, row.severity.value if row.severity else "-", r.fix_safety]
        if table.profile is not None:
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
    help="Show the effective rule set under this renderer profile.",
)
def list_rules(output_format: str, profile: str | None) -> None:
    """List every registered rule (under --profile: its severity and whether it runs)."""
    registry = load_registry()
    from ..profiles import get_profile
    from ..profiles.effective import effective_rules

    chosen = get_profile(profile) if profile else None
    rows = effective_rules(registry.rules, chosen)
    emit("rules", output_format, RuleTable(rows, registry, chosen), what="the rule list")


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
