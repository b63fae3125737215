"""Where ``spec`` writes: the JSON document or the text view to stdout or a
file (atomically), the SVG pictures into a folder (each atomically)."""

from __future__ import annotations

import io
import json
from collections.abc import Sequence
from pathlib import Path
from typing import TextIO

from ..atomic import write_text_atomic
from ..model import FileResult
from .document import spec_document

FORMATS = ("text", "json", "svg")


class OutputError(Exception):
    """The output cannot be written (one line)."""


def emit(
    results: Sequence[FileResult],
    output_format: str,
    output: str | None,
    tool_version: str,
    stdout: TextIO,
) -> None:
    """Write the results in ``output_format``: to ``output`` (a file for text
    and json, a folder for svg, which needs one) or else to ``stdout``. With
    svg, stdout lists the files written."""
    document = spec_document(results, tool_version)
    if output_format == "svg":
        if output is None:
            raise OutputError("--format svg writes one file per product: give --output DIR")
        for path in write_svgs(document, Path(output)):
            stdout.write(f"{path}\n")
        return
    if output_format == "json":
        text = json.dumps(document, indent=2) + "\n"
    elif output is None:
        from . import textview

        textview.render(document, stdout)
        return
    else:
        from . import textview

        buffer = io.StringIO()  # not a terminal: plain text
        textview.render(document, buffer)
        text = buffer.getvalue()
    if output is None:
        stdout.write(text)
        return
    try:
        write_text_atomic(output, text)
    except OSError as exc:
        raise OutputError(f"{output}: cannot write the specification: {_why(exc)}") from None


def write_svgs(document: dict, folder: Path) -> list[Path]:
    from . import svg  # only this format draws pictures

    if folder.exists() and not folder.is_dir():
        raise OutputError(f"{folder}: --format svg needs a folder, and this is a file")
    written = []
    try:
        folder.mkdir(parents=True, exist_ok=True)
        for name, text in svg.svg_files(document):
            path = folder / name
            write_text_atomic(path, text)
            written.append(path)
    except OSError as exc:
        raise OutputError(f"{folder}: cannot write the pictures: {_why(exc)}") from None
    return written


def _why(exc: OSError) -> str:
    return exc.strerror or str(exc) or type(exc).__name__


__all__ = ["FORMATS", "OutputError", "emit", "write_svgs"]
