"""``usdrender-lint spec``: what will render, per RenderSettings and product."""

from __future__ import annotations

import sys
from typing import Any, TextIO

import click

from .. import __version__
from ..paths import printable
from .loading import import_engine, supervision
from .options import (
    config_option,
    dash_is_stdout,
    isolated_option,
    setting_options,
    setting_values,
)
from .output import ToolError, errors_after_report, note, stdout_to_stderr, write, write_file
from .views import emit, format_option, view


@view("spec", "text")
def _text(document: dict, stream: TextIO) -> None:
    from ..formatters.text import terminal_width, write_lines
    from ..render_spec.textview import document_lines

    write_lines(document_lines(document, terminal_width(stream)), stream)


@view("spec", "json")
def _json(document: dict, stream: TextIO) -> None:
    import json

    stream.write(json.dumps(document, indent=2) + "\n")


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


@click.command("spec")
@click.argument("paths", nargs=-1, required=True, type=click.Path(readable=False))
@click.option("--settings", "settings_path", help="Only this RenderSettings prim (a path).")
@click.option(
    "--time",
    "time_option",
    callback=_time_option,
    help="Time to read the camera and productName at: a number or 'default'  "
    "[default: the stage's startTimeCode when authored, else each camera's first "
    "rendered time].",
)
# svg is no stream view: one file per product into the --output folder.
@format_option("spec", "svg")
@click.option(
    "--output",
    callback=dash_is_stdout,
    help="Write to this file (text, json; atomically; '-': stdout) or folder (svg: one file "
    "per product).",
)
@config_option("Read settings (rule selection for the findings) from this file.")
@isolated_option
@setting_options("spec")
def spec_command(
    paths: tuple[str, ...],
    settings_path: str | None,
    time_option: tuple[float | None, bool],
    output_format: str,
    output: str | None,
    config: tuple[str | None, tuple[str, ...]],
    isolated: bool,
    **settings: Any,
) -> None:
    """Show what will render: per RenderSettings and product, the camera, image
    size, conformed aperture, data window, outputs, and the values the linter reports.

    Exit codes: 0 every file's specification was computed; 2 a file could not
    be read (missing, unopenable, timed out) or a usage error.
    """
    time, default_time = time_option
    output_format = output_format.lower()
    if output_format == "svg" and output is None:
        raise ToolError("--format svg writes one file per product: give --output DIR")
    if "-" in paths:  # standard_input.STDIN: check's, not read here ("./-" names a file)
        raise ToolError("spec reads files, not standard input ('-'): save the layer first")
    import_engine()
    from functools import partial

    from ..render_spec.compute import SpecOptions, compute_file_spec
    from ..render_spec.document import spec_document
    from ..running.inspect import InspectedFile, InspectRequest, inspect_files
    from ..running.pipeline import RequestError

    options = SpecOptions(time=time, default_time=default_time, settings=settings_path)
    request = InspectRequest(
        paths,
        config=config[0],
        config_overrides=config[1],
        isolated=isolated,
        output=output if output_format != "svg" else None,
        supervision=supervision(),
        **setting_values("spec", settings),
    )
    try:
        with stdout_to_stderr():  # a rule's print must not land in the document
            inspection = inspect_files(request, partial(compute_file_spec, options=options))
    except RequestError as exc:
        raise ToolError(str(exc)) from None
    files = [(r, r.value if isinstance(r, InspectedFile) else None) for r in inspection.results]
    document = _escaped(spec_document(files, __version__), output_format)
    if output_format == "svg":
        _write_pictures(document, output or ".", [result.file for result, _ in files])
    else:
        emit("spec", output_format, document, output, "the specification")
    for line in inspection.notes:
        note(line)
    errors_after_report(inspection.errors, output_format, output)
    sys.exit(inspection.exit_status)


def _escaped(document: dict, output_format: str) -> dict:
    """Names that are not UTF-8 in their lossless escaped form; the views
    printed as they are escape control characters too."""
    from functools import partial

    from ..formatters import escaped

    if output_format == "json":
        return escaped(document)
    return escaped(document, partial(printable, limit=None))


def _write_pictures(document: dict, output: str, inputs: list[str]) -> None:
    """One SVG per product into the folder ``output``, listing the files;
    never onto one of the ``inputs``."""
    from pathlib import Path

    from ..render_spec.svg import svg_files
    from ..running.outputs import OutputOnInput, refuse_inputs

    folder = Path(output)
    if folder.exists() and not folder.is_dir():
        raise ToolError(f"{folder}: --format svg needs a folder, and this is a file")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ToolError(f"{folder}: cannot create the folder: {exc.strerror or exc}") from None
    pictures = svg_files(document)
    try:
        refuse_inputs([(str(folder / name), "a picture") for name, _ in pictures], inputs)
    except OutputOnInput as exc:
        raise ToolError(str(exc)) from None
    for name, text in pictures:
        write_file(folder / name, text, "the picture")
        write(f"{printable(str(folder / name))}\n")
