"""GitHub Actions workflow commands: one annotation per finding.

``::error file=F,line=N,title=CODE::message`` (``warning`` / ``notice`` by
severity; info findings only with --show-info, as in the text report). The
file is the layer holding the offending opinion, as an absolute path; the
line is given only when known. Escaping follows the Actions toolkit: ``%``,
CR and LF in the message; those plus ``:`` and ``,`` in property values.

Absolute, because the runner maps an absolute ``file`` below the workspace
onto the repository (relative to it, a container's path translated first)
and passes any other as it is, read as relative to the repository's root
(``IssueCommandExtension.ProcessCommand``,
https://github.com/actions/runner/blob/main/src/Runner.Worker/ActionCommandManager.cs):
a path relative to the working directory would annotate the wrong file, or
none, in a step run from a subfolder (``working-directory:``).
"""

from __future__ import annotations

from typing import TextIO

from ..model import Finding, Report, Severity
from ..paths import layer_file, printable
from . import FormatOptions, statistics_lines

#: How the report names standard input (running/standard_input.py, not
#: imported: the formatter loads without the engine).
STDIN = "-"
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


def workspace_path(name: str) -> str:
    """The file ``name`` (a layer identifier) absolute, as the runner maps it
    onto the repository; standard input (``-``) stays as it is."""
    file = layer_file(name) if name != STDIN else None
    return str(file) if file is not None else name


def annotation(finding: Finding) -> str:
    loc = finding.location
    text = f"{loc.path}: {finding.message}" if loc.path else finding.message
    in_layer = loc.layer is not None and layer_file(loc.layer) is not None
    line = loc.line if in_layer and loc.line else None
    return command(
        _COMMAND[finding.severity],
        f"{text} [{finding.name}]",
        file=workspace_path(loc.layer if loc.layer is not None and in_layer else loc.file),
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
                stream.write(command("error", message, file=workspace_path(result.file)) + "\n")
            for finding in result.findings:
                if options.show_info or finding.severity != Severity.INFO:
                    stream.write(annotation(finding) + "\n")
        if options.statistics:
            # Plain lines are log output in a workflow, not commands.
            stream.writelines(line + "\n" for line in statistics_lines(report))
