"""Files in, what an inspector reads from each linted stage out.

For a command that reads the stage ``check`` lints (``spec``): the same
configuration and rules, discovery, worker processes with their time limit,
and per-path ignores as a check run, each file linted by
:meth:`Linter.run_path` with the inspector (its LintRun's value). A file the
inspector cannot read (it does not exist, USD cannot open it, it timed out,
the inspector raised ``InspectionError``) is an error result with one line
saying why.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from ..config import reading_once
from ..engine import Inspector, Linter, plugin_notes
from ..model import FileResult, Report
from ..paths import display_path
from ..records import record
from ..settings_table import DEFAULT_TIMEOUT
from .discovery import Exclusions, collect_files
from .outputs import OutputOnInput, refuse_inputs
from .pipeline import (
    EXIT_OK,
    EXIT_TOOL_ERROR,
    LinterSpec,
    Prepared,
    Request,
    RequestError,
    configuration_parts,
    folder_exclusions,
    lint_as_asked,
    no_usd_files,
    prepare,
)
from .supervisor import Supervision

if TYPE_CHECKING:
    from ..config import Settings


@record(frozen=True)
class InspectedFile(FileResult):
    """A linted file's result with what the inspector read from its stage."""

    value: Any = None


@record(frozen=True)
class InspectRequest:
    """What an inspection run needs, as the user asked for it."""

    paths: tuple[str, ...]
    #: A config file path or the settings themselves, or None to search from the
    #: first path (and give each file its nearest configuration).
    config: Settings | str | None = None
    #: Inline settings (``--config 'KEY = VALUE'``), as for check.
    config_overrides: tuple[str, ...] = ()
    isolated: bool = False
    #: The renderer profile: "auto" or a name; None: the configuration's.
    profile: str | None = None
    jobs: int | None = None
    timeout: float | None = DEFAULT_TIMEOUT
    progress: bool | None = None
    #: How the supervisor ran this process (running/supervisor.py); None: not supervised.
    supervision: Supervision | None = None
    #: Patterns not inspected in a folder walked (--exclude, --extend-exclude).
    exclude: tuple[str, ...] | None = None
    extend_exclude: tuple[str, ...] | None = None
    #: Skip a path given too where a walk would (--force-exclude); None: the config's.
    force_exclude: bool | None = None
    #: The file the caller will write to (``spec --output``): refused when it is an input.
    output: str | None = None


@record(frozen=True)
class Inspection:
    #: InspectedFile for each file inspected, a plain FileResult (status
    #: "error") for each that could not be.
    results: tuple[FileResult, ...]
    exit_status: int
    #: Lines for the user beside the results (USD's plugin registration problems).
    notes: tuple[str, ...] = ()

    @property
    def errors(self) -> tuple[str, ...]:
        return tuple(r.error or r.file for r in self.results if r.status != "linted")


class InspectingLinter:
    """Lints a file and inspects its stage; what the workers run on each file."""

    def __init__(self, linter: Linter, inspect: Inspector[Any]) -> None:
        self.linter = linter
        self.inspect = inspect

    @property
    def raise_errors(self) -> bool:
        return self.linter.raise_errors

    def lint_path(self, path: str, *, full_composition: bool = False) -> FileResult:
        run = self.linter.run_path(path, full_composition=full_composition, inspect=self.inspect)
        result = run.result
        if run.value is not None:
            return InspectedFile(result.file, findings=result.findings, value=run.value)
        if result.status == "linted":  # no stage: USD cannot open it, its ST001 says why
            why = _where(result.findings[0]) if result.findings else "USD cannot open it"
            return FileResult(path, status="error", error=f"{path}{why}")
        return result


@record(frozen=True)
class InspectingLinterFactory:
    """A picklable recipe for the inspecting linter, built once per worker
    (``inspect`` must pickle: a module-level function or a partial of one)."""

    linter: LinterSpec
    inspect: Inspector[Any]

    def __call__(self) -> InspectingLinter:
        linter = self.linter()
        assert isinstance(linter, Linter)  # no variant exploration: the stage as it is
        return InspectingLinter(linter, self.inspect)


@reading_once()  # each configuration file read once in the run
def inspect_files(request: InspectRequest, inspect: Inspector[Any]) -> Inspection:
    """Lint and inspect every file. Raises RequestError when the run cannot
    start (a bad configuration, a rule plugin that fails)."""
    prepared = prepare(
        Request(
            request.paths,
            config=request.config,
            config_overrides=request.config_overrides,
            isolated=request.isolated,
            profile=request.profile,
            exclude=request.exclude,
            extend_exclude=request.extend_exclude,
            force_exclude=request.force_exclude,
        )
    )
    exclusions = Exclusions.of(prepared.settings)
    empty: list[str] = []
    files = collect_files(request.paths, empty, exclusions, folder_exclusions(prepared))
    # Each file with its nearest configuration, as check lints it (running/hierarchy.py).
    parts = configuration_parts(prepared, files) or [(prepared, files)]
    configs = [part.settings.source for part, _ in parts if part.settings.source]
    try:
        refuse_inputs([(request.output, "the specification")], [*files, *configs])
    except OutputOnInput as exc:
        raise RequestError(str(exc)) from None
    results: list[FileResult] = []
    for part, found in parts:
        results += _inspected(request, part, found, inspect)
    place = {file: index for index, file in enumerate(files)}
    results.sort(key=lambda result: place.get(result.file, len(place)))
    errored = any(r.status != "linted" for r in results)
    status = EXIT_TOOL_ERROR if errored else EXIT_OK
    notes = (*plugin_notes(), *map(no_usd_files, empty))  # as check says them
    return Inspection(tuple(results), status, notes=notes)


def _inspected(
    request: InspectRequest, prepared: Prepared, files: Sequence[str], inspect: Inspector[Any]
) -> tuple[FileResult, ...]:
    factory = InspectingLinterFactory(LinterSpec(prepared.settings), inspect)
    linter = InspectingLinter(prepared.linter, inspect)
    results = lint_as_asked(request, files, factory, linter)
    return prepared.finish(Report(results)).files


def _where(finding: Any) -> str:
    """``:LINE:COL: message`` (the line where USD gives one), or ``: message``;
    the position in another layer (a sublayer) with that layer's name."""
    location = finding.location
    if location.line is None:
        return f": {finding.message}"
    where = f":{location.line}" + (f":{location.column}" if location.column else "")
    if location.layer and os.path.realpath(location.layer) != os.path.realpath(location.file):
        where = f": {display_path(location.layer)}{where}"
    return f"{where}: {finding.message}"
