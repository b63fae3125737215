"""``usdrender-lint explain``: a rule's documentation."""

from __future__ import annotations

from typing import TextIO

import click

from .loading import registry
from .options import complete_rule
from .output import ToolError
from .views import emit, view


@view("explain", "text")
def _text(text: str, stream: TextIO) -> None:
    stream.write(text)


@click.command()
@click.argument("rule", shell_complete=complete_rule)
def explain(rule: str) -> None:
    """Print a rule's documentation (by code or name)."""
    from ..model import INTERNAL_ERROR_RULE as internal

    found = registry().find(rule)
    if found is not None:
        from ..explain import explain_text

        emit("explain", "text", explain_text(found), what="the rule's documentation")
    elif rule.strip().upper() == internal.code or rule.strip().lower() == internal.name:
        header = f"{internal.code} {internal.name} ({internal.severity.value}, fix: {internal.fix})"
        emit("explain", "text", f"{header}\n\n{internal.doc}\n", what="the rule's documentation")
    else:
        near = registry().nearest(rule, also=(internal.code, internal.name))
        hint = f"did you mean {near!r}? " if near else ""
        raise ToolError(f"no rule has the code or name {rule!r} ({hint}see 'usdrender-lint rules')")
