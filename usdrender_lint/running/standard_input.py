"""``check -``: one text layer read from standard input, linted as the file it stands for.

The text becomes the layer of its path (``--stdin-filename``, else ``-`` in the
working directory), as the language server lints an editor's unsaved buffer
(documents.py): its relative asset paths resolve from that folder, the
configuration is the one found from it, and nothing is written. The report names
it as given. A crate or a ``.usdz`` cannot be held as text: they are refused, as
is text that is not UTF-8, each with one line naming the cause. ``--fix`` and
``--diff`` edit the text alone (a fix of a file it composes is not applied): the
fixed text, or its patch, is the command's output.
"""

from __future__ import annotations

import os
import re
from dataclasses import replace
from typing import TYPE_CHECKING

from .. import debug
from ..model import FileResult, Finding
from ..records import record
from .pipeline import Prepared
from .workers import CRASHED, cap_memory, file_error, internal_error, timed_out

if TYPE_CHECKING:
    from ..fixing import FixRun
    from .supervisor import Supervision

#: The path that names standard input on the command line, and in the report
#: when ``--stdin-filename`` is not given.
STDIN = "-"

#: The layer that stands for a text with no name, in the working directory.
_UNNAMED = "-.usda"
#: The name in a message, not inside a longer one.
_PLACEHOLDER = re.compile(r"(?<![\w.-])-\.usda(?![\w.])")

#: How a layer that is not text begins (USD's crate, and a zip: ``.usdz``).
_BINARY = {b"PXR-USDC": "a binary crate (.usdc)", b"PK\x03\x04": "a package (.usdz)"}


class StandardInputError(Exception):
    """Standard input cannot be linted at all (a terminal, a binary layer, not UTF-8)."""


@record(frozen=True)
class StandardInput:
    """The text read from standard input, and the path it stands for as given."""

    text: str
    name: str = STDIN

    @property
    def path(self) -> str:
        """The layer's identifier: the name, absolute (USD resolves from it); for
        a text no name was given, one with the extension USD's messages need to
        show a line (``-.usda:3:1: ...``)."""
        return os.path.abspath(_UNNAMED if self.name == STDIN else self.name)

    def lint(self, prepared: Prepared) -> FileResult:
        """The pipeline's lint of the text (pipeline.TextLayer)."""
        request = prepared.request
        return lint_standard_input(prepared, self, request.supervision, request.timeout)

    def fix(self, prepared: Prepared) -> tuple[FixRun, StandardInput]:
        """The request's fixes of the text (pipeline.TextLayer): what the fixer
        did, and the text they leave (with --diff, its patch in the run's diffs);
        after the supervised child ended on it, none (its lint says how it ended)."""
        from ..fixing import FixRun

        supervision, timeout = prepared.request.supervision, prepared.request.timeout
        if supervision is None:
            return _fix(prepared, self)
        if supervision.ending is not None:
            return FixRun(), self
        cap_memory(workers=1)
        if timeout:
            return supervision.timed(timeout, _fix, prepared, self)
        return _fix(prepared, self)


def decode(data: bytes, name: str = STDIN) -> StandardInput:
    """Standard input's bytes as a text layer; StandardInputError says why not."""
    # USD makes no layer of such a name from a text (SdfLayer::CreateNew refuses it).
    if name.endswith("]") and "[" in name:
        # A package-relative path (``pkg.usdz[inner.usda]``): the package is a zip.
        raise StandardInputError(
            "names a layer inside a package; the text on standard input can stand only for "
            "a layer file: give the package's path instead"
        )
    if ":SDF_FORMAT_ARGS:" in name:
        raise StandardInputError(
            "holds file format arguments (:SDF_FORMAT_ARGS:), which no layer file's name "
            "can: give the file's name alone"
        )
    for magic, what in _BINARY.items():
        if data.startswith(magic):
            raise StandardInputError(
                f"standard input holds {what}; only a text layer (.usda) can be read from it: "
                "give the file's path instead"
            )
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        byte = data[exc.start : exc.start + 1].hex()
        raise StandardInputError(
            f"standard input is not UTF-8 text (byte 0x{byte} at offset {exc.start}); "
            "a text layer (.usda) is UTF-8"
        ) from None
    return StandardInput(text, name)


def lint_standard_input(
    prepared: Prepared,
    given: StandardInput,
    supervision: Supervision | None = None,
    timeout: float | None = None,
) -> FileResult:
    """The result of ``given``'s text; in the supervised child under its timer, and
    in the supervisor after the child timed out or crashed on it, that ending."""
    if supervision is None:
        return _lint(prepared, given)
    if supervision.ending is not None:
        why = timed_out(timeout, supervision.stall) if supervision.ending == "timeout" else CRASHED
        return file_error(given.name, why)
    cap_memory(workers=1)  # as the child caps itself for a lone file (workers.InProcess)
    return supervision.timed(timeout, _lint, prepared, given) if timeout else _lint(prepared, given)


def _lint(prepared: Prepared, given: StandardInput) -> FileResult:
    """As ``workers.lint_one`` lints a file: an engine failure is the text's error."""
    from ..engine import SchemasMissing
    from .documents import Documents

    try:
        documents = Documents(prepared=prepared)
        documents.update({given.path: given.text})
        linted = documents.lint(given.path)
    except SchemasMissing:  # no text can be linted: the run's error (pipeline.run)
        raise
    except Exception as exc:  # noqa: BLE001 - reported as the text's one line, as a file's
        debug.show(exc, f"{given.name}: internal error")
        return file_error(given.name, internal_error(exc))
    return FileResult(given.name, findings=tuple(_named(f, given) for f in linted.findings))


def _fix(prepared: Prepared, given: StandardInput) -> tuple[FixRun, StandardInput]:
    from ..engine import SchemasMissing
    from ..fixing import FixRun
    from ..fixing.diff import patch
    from .documents import Documents

    wanted = prepared.request.fix
    assert wanted is not None
    try:
        documents = Documents(prepared=prepared)
        documents.update({given.path: given.text})
        run, changed = documents.fix(given.path, None, wanted.unsafe, texts_only=True)
    except SchemasMissing:  # no text can be linted: the run's error (pipeline.run)
        raise
    except Exception as exc:  # noqa: BLE001 - reported as the text's one line, as a file's
        debug.show(exc, f"{given.name}: internal error")
        return FixRun(errors=[f"{given.name}: fixing failed: {internal_error(exc)}"]), given
    fixed = replace(given, text=changed.get(given.path, (given.text, given.text))[1])
    if not wanted.write and fixed.text != given.text:
        run.diffs.append(patch(given.name, given.text, fixed.text))
    return run, fixed


def _named(finding: Finding, given: StandardInput) -> Finding:
    """The finding as the report names the text: by the name given, as ``check``
    names a file by its path as given (a text with no name: ``-`` for its layer too)."""
    location = finding.location
    if location.file == given.path:
        location = replace(location, file=given.name)
    if given.name != STDIN:
        return replace(finding, location=location) if location is not finding.location else finding
    if location.layer == given.path:
        location = replace(location, layer=STDIN)
    # USD's messages name the layer the text stands in for: not a name of the user's.
    message = _PLACEHOLDER.sub(STDIN, finding.message.replace(given.path, STDIN))
    return replace(finding, location=location, message=message)
