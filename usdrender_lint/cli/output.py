"""Where every command's output goes: stdout (its failures told apart: a
reader that went away is a quiet exit 2, a full disk a one-line error) or a
file written as a shell's ``>`` would, and one-line errors on stderr."""

from __future__ import annotations

import sys
from collections.abc import Iterable, Iterator
from contextlib import contextmanager, suppress
from pathlib import Path

import click

from ..paths import printable

#: The pipeline's exit codes (running/pipeline.py), repeated so that --help
#: and --version need no import of USD.
EXIT_OK, EXIT_FINDINGS, EXIT_TOOL_ERROR = 0, 1, 2


class ToolError(click.ClickException):
    """A one-line error on stderr and exit 2."""

    exit_code = EXIT_TOOL_ERROR

    def show(self, file=None) -> None:
        error(self.format_message())


class StdoutGone(Exception):
    """stdout is closed, or its reader went away (``check | head``): nobody
    reads the report, so the run ends with exit 2 and says nothing."""


def error(message: str) -> None:
    say(f"usdrender-lint: error: {printable(message)}")


def note(message: str) -> None:
    say(f"usdrender-lint: {printable(message)}")


def say(line: str) -> None:
    """``line`` on stderr, if it can be written: a full or broken stderr
    (``2>/dev/full``) must not turn the exit code into Python's 1."""
    with suppress(OSError):
        click.echo(line, err=True)


def errors_after_report(
    lines: Iterable[str], output_format: str, output: str | None, reported: bool = True
) -> None:
    """The files that could not be processed, repeated on stderr for a log or a
    machine-read report; not when a text report already showed them on the
    terminal stderr writes to, where they would read twice (``reported``: False
    when no report was written, --silent's)."""
    shown = reported and output_format in ("text", "full") and output is None  # ("-" is None)
    if shown and sys.stdout is not None and sys.stdout.isatty() and sys.stderr.isatty():
        return
    for line in lines:
        error(line)


class Stdout:
    """sys.stdout, written to the end: the text is gathered and written with
    :func:`~usdrender_lint.atomic.write_all` (a single ``write()`` to a pipe
    whose reader left takes part of it and says nothing, so Python's own
    stream could leave a report cut short with exit 0). A closed or broken
    pipe is :class:`StdoutGone`, any other failure (a full disk) a ToolError."""

    #: Bytes gathered before they are written.
    CHUNK = 1 << 16

    def __init__(self, encoding: str | None = None, what: str = "the report") -> None:
        self._parts: list[str] = []
        self._size = 0
        #: None: UTF-8, or a terminal's own; a layer's text is UTF-8 whatever it is.
        self._encoding = encoding
        #: What is written, as a failure names it (a rule list is no report).
        self._what = what

    def write(self, text: str) -> int:
        self._parts.append(text)
        self._size += len(text)
        if self._size >= self.CHUNK:
            self.flush()
        return len(text)

    def writelines(self, lines: Iterable[str]) -> None:
        # A formatter is handed a TextIO: every way it has to write is here.
        for line in lines:
            self.write(line)

    def flush(self) -> None:
        text, self._parts, self._size = "".join(self._parts), [], 0
        self._do(text)

    def isatty(self) -> bool:
        return bool(sys.stdout is not None and sys.stdout.isatty())

    def _do(self, text: str) -> None:
        from ..atomic import write_all

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
            if self._encoding is not None:
                data = text.encode(self._encoding)
            elif stream.isatty():
                # A person's terminal: what its encoding cannot show is escaped.
                data = text.encode(stream.encoding or "utf-8", "backslashreplace")
            else:
                # A file or a pipe gets the bytes --output writes: UTF-8, the
                # encoding JSON, SARIF and the JUnit XML declaration say.
                data = text.encode("utf-8")
            write_all(fd, data)
        except BrokenPipeError:
            raise StdoutGone from None
        except OSError as exc:
            raise ToolError(f"cannot write {self._what}: {exc.strerror or exc}") from None


@contextmanager
def stdout_to_stderr() -> Iterator[None]:
    """While a check runs, what a rule prints goes to stderr: stdout carries the
    report alone (``--format json`` must parse). Python's stream only: fd 1 stays
    the user's, for a report or baseline the run writes to /dev/stdout. Workers
    send their fd 1 to /dev/null (running/workers.py)."""
    stream = sys.stdout
    with suppress(OSError, ValueError):
        if stream is not None:
            stream.flush()
    sys.stdout = sys.stderr
    try:
        yield
    finally:
        # stderr may be gone: what the rule printed is lost, the report is not.
        with suppress(OSError, ValueError):
            if sys.stderr is not None:
                sys.stderr.flush()
        sys.stdout = stream


def write(text: str, encoding: str | None = None) -> None:
    """Write ``text`` to stdout and flush it, so that a failure is known now;
    ``encoding``: instead of the stream's."""
    stdout = Stdout(encoding)
    stdout.write(text)
    stdout.flush()


def write_file(path: str | Path, text: str, what: str) -> None:
    """Write ``text`` to ``path`` as a shell's ``>`` would, atomically where
    that can be (atomic.write_output); a failure is one line, exit 2."""
    from ..atomic import write_output

    try:
        write_output(path, text)
    except BrokenPipeError:
        raise StdoutGone from None  # a pipe the user named, whose reader left
    except OSError as exc:
        raise ToolError(f"{path}: cannot write {what}: {exc.strerror or exc}") from None
