"""Files in, specifications out: ``spec`` runs through the check pipeline's
pieces (configuration and rules, discovery, the workers with their time
limit, per-path ignores) and lints each file as ``check`` does, computing the
specification from the same, partly composed, stage."""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

from ..engine import Linter
from ..model import FileResult, Report
from ..running.discovery import collect_files
from ..running.pipeline import (
    EXIT_OK,
    EXIT_TOOL_ERROR,
    LinterSpec,
    Request,
    RequestError,
    prepare,
)
from ..running.workers import DEFAULT_TIMEOUT, ExecutionError, default_jobs, lint_paths
from .compute import SpecError, SpecOptions, compute_file_spec
from .data import SpecFileResult

__all__ = ["SpecOptions", "SpecOutcome", "SpecRequest", "SpecRunner", "run_spec"]


@dataclass(frozen=True)
class SpecRequest:
    """Everything a ``spec`` run needs, as the user asked for it."""

    paths: tuple[str, ...]
    options: SpecOptions = SpecOptions()
    #: A config file path, or None to search from the first path.
    config: str | None = None
    isolated: bool = False
    jobs: int | None = None
    timeout: float | None = DEFAULT_TIMEOUT
    progress: bool | None = None


@dataclass(frozen=True)
class SpecOutcome:
    results: tuple[FileResult, ...]
    exit_status: int

    @property
    def errors(self) -> tuple[str, ...]:
        return tuple(r.error or r.file for r in self.results if r.status != "linted")


class SpecRunner:
    """Lints a file like the linter and computes its specification; what the
    workers call (``lint_path``), so bad input is handled as for ``check``."""

    def __init__(self, linter: Linter, options: SpecOptions) -> None:
        self.linter = linter
        self.options = options

    @property
    def raise_errors(self) -> bool:
        return self.linter.raise_errors

    def lint_path(self, path: str) -> FileResult:
        try:
            inspected = self.linter.inspect_path(
                path, partial(compute_file_spec, options=self.options)
            )
        except SpecError as exc:
            return FileResult(path, status="error", error=f"{path}: {exc}")
        result = inspected.result
        if inspected.value is None:
            if result.status == "linted":  # USD cannot open it: its ST001 says why
                why = result.findings[0].message if result.findings else "USD cannot open it"
                return FileResult(path, status="error", error=f"{path}: {why}")
            return result
        return SpecFileResult(result.file, findings=result.findings, spec=inspected.value)


@dataclass(frozen=True)
class SpecRunnerFactory:
    """A picklable recipe for the runner, built once per worker process."""

    linter: LinterSpec
    options: SpecOptions

    def __call__(self) -> SpecRunner:
        linter = self.linter()
        assert isinstance(linter, Linter)  # no variants: the spec is of the stage as it is
        return SpecRunner(linter, self.options)


def run_spec(request: SpecRequest) -> SpecOutcome:
    """Compute the specification of every file. Raises RequestError when the
    run cannot start; a file that cannot be read is an error result."""
    prepared = prepare(Request(request.paths, config=request.config, isolated=request.isolated))
    factory = SpecRunnerFactory(LinterSpec(prepared.settings), request.options)
    files = collect_files(request.paths)
    try:
        results = lint_paths(
            files,
            linter=SpecRunner(prepared.linter, request.options),
            linter_factory=factory,
            jobs=request.jobs or default_jobs(),
            timeout=request.timeout,
            progress=request.progress,
        )
    except ExecutionError as exc:
        raise RequestError(str(exc)) from None
    report = prepared.finish(Report(tuple(results)))
    errored = any(r.status != "linted" for r in report.files)
    return SpecOutcome(report.files, EXIT_TOOL_ERROR if errored else EXIT_OK)
