"""GitHub Actions workflow commands: one annotation per finding.

``::error file=F,line=N,title=CODE::message`` (``warning`` / ``notice`` by
severity; info findings only with --show-info, as in the text report). The
file is the layer holding the offending opinion, relative to the working
directory; the line is given only when known. Escaping follows the Actions
toolkit: ``%``, CR and LF in the message; those plus ``:`` and ``,`` in
property values.
"""

from __future__ import annotations

from typing import TextIO

from ..model import Finding, Report, Severity
from ..paths import display_path, layer_file, printable
from . import FormatOptions, statistics_lines

_COMMAND = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.INFO: "notice"}


def escape_data(text: str) -> str:
    # CR and LF are the toolkit's to encode; every other control is escaped.
    text = printable(text, keep="\r\n")
    return text.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def escape_property(text: str) -> str:
    return escape_data(text).replace(":", "%3A").replace(",", "%2C")


def command(name: str, message: str, **properties: object) -> str:
    """One workflow command line; properties that are None are left out."""
    given = ",".join(
        f"{key}={escape_property(str(value))}"
        for key, value in properties.items()
        if value is not None
    )
    return f"::{name}{' ' + given if given else ''}::{escape_data(message)}"


def annotation(finding: Finding) -> str:
    loc = finding.location
    text = f"{loc.path}: {finding.message}" if loc.path else finding.message
    line = loc.line if layer_file(loc.layer) and loc.line else None
    return command(
        _COMMAND[finding.severity],
        f"{text} [{finding.name}]",
        file=display_path(str(layer_file(loc.layer) or loc.file)),
        line=line,
        col=loc.column if line else None,
        title=finding.code,
    )


class GithubFormatter:
    #: It never reads Report.rules nor the configuration digest, so the
    #: command does not build them.
    reads_rules = False
    reads_configuration = False

    def render(self, report: Report, stream: TextIO, options: FormatOptions) -> None:
        for result in report.files:
            if result.status != "linted":
                message = f"could not be linted: {result.error or 'failed'}"
                stream.write(command("error", message, file=display_path(result.file)) + "\n")
            for finding in result.findings:
                if options.show_info or finding.severity != Severity.INFO:
                    stream.write(annotation(finding) + "\n")
        if options.statistics:
            # Plain lines are log output in a workflow, not commands.
            stream.writelines(line + "\n" for line in statistics_lines(report))
