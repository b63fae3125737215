"""Every command's output through one emitter. ``check`` and ``merge`` render
a report with the registered formatters (entry points, :mod:`..formatters`);
the other commands register their views here, by command and format name,
and ``--format`` offers exactly the registered names."""

from __future__ import annotations

import io
from collections.abc import Callable
from typing import Any, TextIO

import click

from .output import Stdout, write_file

#: A view writes a command's value (its document, its rows) to a stream.
Render = Callable[[Any, TextIO], None]

_VIEWS: dict[str, dict[str, Render]] = {}


def view(command: str, name: str) -> Callable[[Render], Render]:
    """Register a function as ``command``'s ``--format name`` view."""

    def register(render: Render) -> Render:
        _VIEWS.setdefault(command, {})[name] = render
        return render

    return register


def names(command: str) -> list[str]:
    return list(_VIEWS[command])


def format_option(command: str, *extra: str):
    """``--format`` with ``command``'s views (and ``extra`` names a command
    handles itself, such as spec's svg folder)."""
    return click.option(
        "--format",
        "output_format",
        type=click.Choice([*names(command), *extra], case_sensitive=False),
        default="text",
        show_default=True,
        help="Output format.",
    )


def emit(command: str, name: str, value: Any, output: str | None = None, what: str = "") -> None:
    """``value`` through ``command``'s view ``name``, to stdout or ``output``."""
    render = _VIEWS[command][name.lower()]
    send(lambda stream: render(value, stream), output, what or f"the {command} output")


def send(render: Callable[[TextIO], None], output: str | None, what: str) -> None:
    """What ``render`` writes, to stdout (as it is written) or to the file
    ``output`` (whole, atomically; stdout gets nothing)."""
    if output is None:
        stdout = Stdout(what=what)
        render(stdout)  # type: ignore[arg-type]
        stdout.flush()
        return
    buffer = io.StringIO()  # not a terminal: plain text
    render(buffer)
    write_file(output, buffer.getvalue(), what)
