"""What a report shows beside its findings, read from the files it names: the
source lines around each finding, each fix as a diff, and each RenderSettings'
and product's specification (the framing ``spec`` draws) with the findings
on it. The HTML report renders these (formatters/html.py); a report merged
from shards gets them too where the files are still there, and is shown
without them where they are not.

Everything is read again from the files at the time the report is written:
``check --format html`` reads them right after linting them. Nothing is
written.
"""

from __future__ import annotations

import difflib
import os
from collections.abc import Callable, Iterable, Sequence
from dataclasses import field
from functools import partial
from typing import TYPE_CHECKING, Any

from ..layers.source_lines import read_lines
from ..model import Finding, Report
from ..paths import display_path, printable
from ..records import record

if TYPE_CHECKING:
    from ..config import Settings

#: The configuration a file was linted with; None: its nearest (formatters.FormatOptions).
SettingsOf = Callable[[str], "Settings | None"]

#: Lines of source shown before and after a finding's line.
CONTEXT_LINES = 3
#: Fixes shown as diffs per report at most (each costs two lints of its stage).
MAX_DIFFS = 200
#: The prims the diffs of a report may lint in all: each diff lints its whole
#: stage twice, so the cost grows with fixes times stage size, and a stage of
#: 1,500 RenderSettings with 200 fixes took 8 minutes under MAX_DIFFS alone.
#: Counted in prims, not seconds, so the page is the same on every machine.
MAX_DIFF_PRIMS = 10_000
#: Framing pictures drawn per report at most: each is some 4 kB of inline SVG,
#: and a stage of 1,500 RenderSettings drew 1,500 of them (6 of its 10 MB page).
MAX_PICTURES = 200


def finding_key(finding: Finding) -> tuple[str, str, str, str]:
    """How a finding is named across the lints of one file."""
    return (finding.location.file, finding.code, finding.location.path or "", finding.message)


@record(frozen=True)
class Excerpt:
    """Lines ``first``.. of a layer's text, the finding's line among them."""

    layer: str
    first: int
    lines: tuple[str, ...]
    line: int


@record(frozen=True)
class ProductView:
    """A product (or settings without products) as ``spec`` draws it."""

    settings: str
    product: str | None
    svg: str
    findings: tuple[tuple[str, str, str, str], ...]


@record
class FileView:
    file: str
    excerpts: dict[tuple, Excerpt] = field(default_factory=dict)
    diffs: dict[tuple, str] = field(default_factory=dict)
    products: list[ProductView] = field(default_factory=list)
    #: Why the file's specification could not be drawn (None: it was, or no settings).
    spec_error: str | None = None
    #: The settings' profile and why, by settings path.
    profiles: dict[str, tuple[str, str]] = field(default_factory=dict)


@record
class ReportViews:
    files: dict[str, FileView] = field(default_factory=dict)
    #: Lines for the reader about what could not be shown.
    notes: list[str] = field(default_factory=list)


def gather(report: Report, settings_of: SettingsOf | None = None) -> ReportViews:
    """Read what the report's files show beside the findings, each file read
    with the configuration that linted it (``settings_of``). Never raises."""
    views = ReportViews({r.file: FileView(r.file) for r in report.files})
    present = [r.file for r in report.files if r.status == "linted" and os.path.isfile(r.file)]
    missing = [r.file for r in report.files if r.status == "linted" and r.file not in present]
    if missing:
        views.notes.append(
            f"{len(missing)} file(s) are not on disk here (a merged report read elsewhere): "
            "their findings are shown without source lines, fixes or framing pictures"
        )
    for result in report.files:
        view = views.files[result.file]
        for finding in result.findings:
            excerpt = _excerpt(finding)
            if excerpt is not None:
                view.excerpts[finding_key(finding)] = excerpt
    if present:
        _specs(report, present, views, settings_of)
        _diffs(report, present, views, settings_of)
    return views


_TEXTS: dict[str, list[str] | None] = {}


def _lines(path: str) -> list[str] | None:
    if path not in _TEXTS:
        _TEXTS[path] = read_lines(path)
    return _TEXTS[path]


def _excerpt(finding: Finding) -> Excerpt | None:
    loc = finding.location
    layer = loc.layer or loc.file
    if loc.line is None or not layer or not os.path.isfile(layer):
        return None
    lines = _lines(layer)
    if not lines or loc.line > len(lines):
        return None
    first = max(1, loc.line - CONTEXT_LINES)
    last = min(len(lines), loc.line + CONTEXT_LINES)
    return Excerpt(display_path(layer), first, tuple(lines[first - 1 : last]), loc.line)


def nearest_with(overrides: Sequence[str]) -> SettingsOf:
    """Each file's nearest configuration with inline settings laid over it (``merge
    --config 'KEY = VALUE'``), as the check those settings were given to read it;
    each folder's read once."""
    from .pipeline import Request, prepare

    known: dict[str, Settings] = {}

    def settings_of(file: str) -> Settings:
        folder = os.path.dirname(os.path.abspath(file))
        if folder not in known:
            known[folder] = prepare(Request((file,), config_overrides=tuple(overrides))).settings
        return known[folder]

    return settings_of


def _by_settings(
    files: Iterable[str], settings_of: SettingsOf | None
) -> list[tuple[Settings | None, list[str]]]:
    """The files grouped by the configuration that linted them, in order."""
    groups: dict[int, tuple[Settings | None, list[str]]] = {}
    for file in files:
        settings = settings_of(file) if settings_of else None
        groups.setdefault(id(settings), (settings, []))[1].append(file)
    return list(groups.values())


def _specs(
    report: Report, files: Sequence[str], views: ReportViews, settings_of: SettingsOf | None
) -> None:
    """The framing pictures: ``spec``'s computation and SVG, per product."""
    results: list[Any] = []
    try:
        from ..render_spec.compute import SpecOptions, compute_file_spec
        from ..render_spec.svg import product_svg
        from .inspect import InspectedFile, InspectRequest, inspect_files

        for settings, group in _by_settings(files, settings_of):
            inspection = inspect_files(
                InspectRequest(tuple(group), config=settings, jobs=1, progress=False),
                partial(compute_file_spec, options=SpecOptions()),
            )
            results += inspection.results
    except Exception as exc:  # noqa: BLE001 - the report is shown without pictures
        views.notes.append(f"framing pictures not drawn: {type(exc).__name__}: {exc}")
        return
    reported = {r.file: r for r in report.files}
    room = [MAX_PICTURES]  # pictures still to draw, across the report's files
    for result in results:
        view = views.files.get(result.file)
        if view is None:
            continue
        if not isinstance(result, InspectedFile) or result.value is None:
            view.spec_error = result.error or "its specification could not be computed"
            continue
        try:
            _file_products(view, reported[result.file], result.value, product_svg, room)
        except Exception as exc:  # noqa: BLE001 - that file is shown without pictures
            view.products.clear()
            view.spec_error = f"its pictures could not be drawn: {type(exc).__name__}: {exc}"
    if room[0] < 0:
        views.notes.append(
            f"{-room[0]:,} framing picture(s) not drawn: the page draws the first {MAX_PICTURES}; "
            "`usdrender-lint spec --format svg --output FOLDER FILE` draws them all"
        )


def _file_products(
    view: FileView, result: Any, spec: Any, product_svg: Any, room: list[int]
) -> None:
    """The file's settings' profiles, and its products' pictures while
    ``room[0]`` (the report's pictures still to draw) lasts; it counts below
    zero the pictures left out."""
    from ..formatters import escaped
    from ..render_spec.document import FindingIndex, file_document, product_findings

    findings = result.findings
    # Names and values printed as spec --format svg prints them: controls escaped.
    document = escaped(file_document(result, spec), partial(printable, limit=None))
    for settings, settings_doc in zip(spec.settings, document["settings"], strict=True):
        view.profiles[settings.path] = (settings.profile, settings.profile_reason)
        siblings = [p.path for p in settings.products if p.path]
        index = FindingIndex(findings, settings.path, siblings)
        pairs = list(zip(settings.products, settings_doc["products"], strict=True))
        if not pairs:
            pairs = [(settings.base, settings_doc["base"])]
        for product, product_doc in pairs:
            room[0] -= 1
            if room[0] < 0:
                continue
            mine = product_findings(product, index)
            view.products.append(
                ProductView(
                    settings.path,
                    product.path,
                    product_svg(document, settings_doc, product_doc),
                    tuple(finding_key(f) for f in mine),
                )
            )


def _diffs(
    report: Report, files: Sequence[str], views: ReportViews, settings_of: SettingsOf | None
) -> None:
    """Each fixable finding's fix as a unified diff of the text layers it edits
    (``--fix``'s verified edit, computed in memory, nothing written)."""
    # The fixes the run offers: none the baseline holds back, which --diff leaves.
    wanted = [
        (r.file, f)
        for r in report.files
        if r.file in files
        for f in r.findings
        if report.offered_fix(f, r.file)
    ]
    if not wanted:
        return
    fixable = len(wanted)
    wanted = wanted[:MAX_DIFFS]
    try:
        from ..engine import open_stage
        from ..fixing.session import FixOptions, StageFixer
        from ..fixing.single import same_finding
        from .pipeline import Request, excluded_from_linting, prepare

        linters: dict[object, Any] = {}
        stages: dict[str, Any] = {}
        prims: dict[str, int] = {}
        spent = skipped = shown = 0
        for file, finding in wanted:
            settings = settings_of(file) if settings_of else None
            # A file's nearest configuration is the same for every file of its folder.
            key = id(settings) if settings else os.path.dirname(os.path.abspath(file))
            if key not in linters:
                request = Request((file,), config=settings, jobs=1, progress=False)
                prepared = prepare(request)
                # A layer the configuration excludes: --fix and --diff leave it alone.
                linters[key] = (prepared.linter, excluded_from_linting(prepared))
            linter, excluded = linters[key]
            fixer = StageFixer(
                linter,
                file,
                FixOptions(unsafe=True, write=False, any_file=True, excluded=excluded),
                partial(same_finding, finding),
            )
            if file not in stages:  # one stage per file: each fixer puts back what it changed
                stages = {file: open_stage(file).stage}
            if stages[file] is None:
                continue
            if file not in prims:
                prims[file] = sum(1 for _prim in stages[file].Traverse())
            if spent + prims[file] > MAX_DIFF_PRIMS:
                skipped += 1  # a smaller file's fixes may still fit
                continue
            spent += prims[file]
            fixer.run(stages[file])
            diff = "".join(_unified(fixer.sources or ()))
            if diff:
                views.files[file].diffs[finding_key(finding)] = diff
                shown += 1
    except Exception as exc:  # noqa: BLE001 - the report is shown without the rest
        views.notes.append(f"fix diffs not computed: {type(exc).__name__}: {exc}")
        return
    if skipped or fixable > len(wanted):
        # One note with the number shown: two notes had said "the first 200 are
        # shown" and "194 not shown" of a page that showed 6.
        views.notes.append(
            f"{fixable:,} findings have fixes: {shown:,} are shown as diffs, as each diff "
            f"lints its whole stage again (the first {MAX_DIFFS:,} fixes at most, and no "
            f"more than {MAX_DIFF_PRIMS:,} prims linted for them); "
            "`usdrender-lint check --diff --unsafe-fixes` prints them all"
        )


def _unified(sources: Iterable[Any]) -> Iterable[str]:
    from ..layers.files import layer_identifier
    from ..paths import layer_file

    for source in sources:
        if not source.changed or source.text is None or source.original_text is None:
            continue
        # The layer as the user named it (its identifier), not the file behind a link.
        named = layer_file(layer_identifier(source.layer))
        name = display_path(str(named or source.disk.path)) if source.disk else "layer"
        yield from difflib.unified_diff(
            source.original_text.splitlines(keepends=True),
            source.text.splitlines(keepends=True),
            fromfile=name if os.path.isabs(name) else f"a/{name}",
            tofile=name if os.path.isabs(name) else f"b/{name}",
            n=2,
        )


__all__ = [
    "CONTEXT_LINES",
    "Excerpt",
    "FileView",
    "ProductView",
    "ReportViews",
    "gather",
    "nearest_with",
]
