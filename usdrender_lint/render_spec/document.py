"""The versioned JSON document of ``usdrender-lint spec`` (schema_version 1;
fields may be added, never renamed or removed without a new version), built
from the computed specifications and the file's findings. The text and SVG
views draw this document, so all three show the same values.

Numbers USD holds as ``float`` (apertures, pixelAspectRatio, dataWindowNDC,
focal length) are written with the fewest digits that read back as the same
float; doubles as Python writes them; a number that is not finite as null.
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from ..model import FileResult, Finding, Severity
from ..paths import display_path
from .data import FileSpec, ProductSpec, SettingsSpec, Source, Time, VarSpec
from .framing import f32

SCHEMA_VERSION = 1
TOOL_NAME = "usdrender-lint"
#: Where a product's camera values live among its sources.
APERTURE_SOURCES = (
    "horizontalAperture",
    "verticalAperture",
    "horizontalApertureOffset",
    "verticalApertureOffset",
)


def spec_document(
    files: Sequence[tuple[FileResult, FileSpec | None]], tool_version: str
) -> dict[str, Any]:
    """The document of each file's lint result and its specification (None
    when it could not be computed: the result's ``error`` says why)."""
    _display_path.cache_clear()  # relative to the working directory of this call
    return {
        "schema_version": SCHEMA_VERSION,
        "tool": {"name": TOOL_NAME, "version": tool_version},
        "files": [file_document(result, spec) for result, spec in files],
    }


def file_document(result: FileResult, spec: FileSpec | None) -> dict[str, Any]:
    document: dict[str, Any] = {
        "file": result.file,
        "status": "computed" if spec is not None else "error",
        "error": result.error if spec is None else None,
        "time": None,
        "timeFrom": None,
        "renderSettingsPrimPath": None,
        "settings": [],
        "findings": _codes(result.findings),
    }
    if spec is not None:
        document.update(
            time=_time(spec.time),
            timeFrom=spec.time_from,
            renderSettingsPrimPath=spec.render_settings_prim_path,
            settings=[_settings(s, result.findings) for s in spec.settings],
        )
    return document


def _settings(settings: SettingsSpec, findings: Sequence[Finding]) -> dict[str, Any]:
    product_paths = [p.path for p in settings.products if p.path]
    index = FindingIndex(findings, settings.path, product_paths)
    own = index.at(settings.path)
    return {
        "path": settings.path,
        "primary": settings.primary,
        "profile": settings.profile,
        "profileReason": settings.profile_reason,
        "includedPurposes": list(settings.included_purposes),
        "materialBindingPurposes": list(settings.material_binding_purposes),
        "renderingColorSpace": settings.rendering_color_space,
        "namespacedSettings": dict(settings.namespaced_settings),
        "sources": _sources(settings.sources),
        "findings": _codes(own),
        "base": _product(settings.base, index),
        "products": [_product(p, index) for p in settings.products],
    }


def _product(product: ProductSpec, index: FindingIndex) -> dict[str, Any]:
    mine = product_findings(product, index)
    framing = product.framing
    window = product.data_window
    return {
        "path": product.path,
        "name": product.name,
        "type": product.type,
        "camera": product.camera,
        "cameraProblem": product.camera_problem,
        "cameraAtRunTime": (
            None
            if product.camera_at_run_time is None
            else {"profile": product.camera_at_run_time[0], "why": product.camera_at_run_time[1]}
        ),
        "time": _time(product.time),
        "renderedTimes": [_time(t) for t in product.rendered_times],
        "resolution": list(product.resolution),
        "pixelAspectRatio": _float(product.pixel_aspect_ratio),
        "aspectRatioConformPolicy": product.aspect_ratio_conform_policy,
        "aperture": None
        if framing is None
        else {
            "camera": _floats(framing.aperture),
            "conformed": _floats(framing.conformed.aperture),
            "offset": _floats(framing.offset),
            "adjusted": framing.conformed.adjusted,
            "notConformed": framing.conformed.skipped,
        },
        "projection": framing.projection if framing is not None else None,
        "focalLength": _float(framing.focal_length) if framing is not None else None,
        "screenWindow": (
            [_double(c) for c in framing.screen_window] if framing is not None else None
        ),
        "dataWindowNDC": _floats(product.data_window_ndc),
        "dataWindow": None
        if window is None
        else {
            "x": list(window.x),
            "y": list(window.y),
            "yFromTop": list(window.y_from_top),
            "width": window.width,
            "height": window.height,
        },
        "disableMotionBlur": product.disable_motion_blur,
        "disableDepthOfField": product.disable_depth_of_field,
        "shutter": [_double(c) for c in product.shutter] if product.shutter else None,
        "vars": [_var(v) for v in product.vars],
        "namespacedSettings": dict(product.namespaced_settings),
        "sources": _sources(product.sources),
        "findings": _codes(mine),
        "flags": product_flags(product, mine),
        "usdRenderComputeSpec": {
            "included": product.compute_spec.included,
            "reason": product.compute_spec.reason,
            "differs": {k: _json_number(v) for k, v in product.compute_spec.differs.items()},
        },
    }


class FindingIndex:
    """A file's findings indexed once per RenderSettings: by prim, and, for the
    findings at the settings, by the products of it their messages name. Each
    product then costs what its own findings do: matching every finding's
    message against every product, for every product, was cubic in the
    products (1,000 products: 329 s of CPU)."""

    def __init__(self, findings: Sequence[Finding], settings_path: str, products: Sequence[str]):
        self.settings_path = settings_path
        self.by_prim: dict[str | None, list[tuple[int, Finding]]] = {}
        for number, finding in enumerate(findings):
            self.by_prim.setdefault(_prim_path(finding.location.path), []).append((number, finding))
        siblings = _PathMatcher(products)
        #: The settings' findings that name none of its products, and those that do.
        self.general: list[tuple[int, Finding]] = []
        self.naming: dict[str, list[tuple[int, Finding]]] = {}
        for number, finding in self.by_prim.get(settings_path, ()):
            named = siblings.named(finding.message)
            if not named:
                self.general.append((number, finding))
            for path in named:
                self.naming.setdefault(path, []).append((number, finding))

    def at(self, prim: str) -> list[Finding]:
        return [finding for _, finding in self.by_prim.get(prim, ())]


def product_findings(product: ProductSpec, index: FindingIndex) -> list[Finding]:
    """The findings at the product, its vars or its camera, and those at its
    settings that concern it: not at a property the product overrides, and
    naming this product or none of the settings' products (a finding about one
    configuration names its product: ``settings ... with product <path>``)."""
    settings_path = index.settings_path
    owners = set(product.owners) - {settings_path}
    overridden = {
        source.path.rpartition(".")[2]
        for source in product.sources.values()
        if source.kind == "product" and source.path
    }
    chosen = [item for owner in owners for item in index.by_prim.get(owner, ())]
    at_settings = list(index.general)
    if product.path is not None:
        at_settings += index.naming.get(product.path, ())
    for number, finding in at_settings:
        path = finding.location.path
        if path and "." in path and path.split(".", 1)[1] in overridden:
            continue
        chosen.append((number, finding))
    chosen.sort(key=lambda item: item[0])
    return [finding for _, finding in chosen]


def product_flags(product: ProductSpec, findings: Iterable[Finding]) -> dict[str, list[str]]:
    """Values to flag, by field: a missing camera and an empty data window,
    and every value whose property an error or warning is reported at (its
    codes; info findings are listed in ``findings`` only)."""
    flags: dict[str, list[str]] = {}
    if product.camera_problem is not None:
        flags.setdefault("camera", []).append(product.camera_problem)
    if product.data_window is not None and product.data_window.empty:
        flags.setdefault("dataWindow", []).append("the data window contains no pixel centre")
    by_path: dict[str, list[str]] = {}
    for finding in findings:
        if finding.location.path and finding.severity.rank > Severity.INFO.rank:
            by_path.setdefault(finding.location.path, []).append(finding.code)
    for key, source in product.sources.items():
        field = _FIELD_OF_SOURCE.get(key, key)
        for code in by_path.get(source.path or "", ()):
            if code not in flags.get(field, []):
                flags.setdefault(field, []).append(code)
    return flags


_FIELD_OF_SOURCE = {
    **{name: "aperture" for name in APERTURE_SOURCES},
    "shutter:open": "shutter",
    "shutter:close": "shutter",
}


#: A prim path as a message quotes it: what _names reads as one name.
_PATH_RUN = re.compile(r"[\w/]+")


class _PathMatcher:
    """Which of a set of prim paths a message names (:func:`_names`), in one
    pass over the message: a path of name characters and ``/`` named in it is
    the tail of a run of such characters, starting at one of the run's ``/``."""

    def __init__(self, paths: Iterable[str]) -> None:
        paths = set(paths)
        self.plain = {p for p in paths if _PATH_RUN.fullmatch(p)}
        self.lengths = {len(p) for p in self.plain}
        #: Paths with other characters (a variant selection): looked for as they are.
        self.other = paths - self.plain

    def named(self, message: str) -> set[str]:
        named = set()
        for run in _PATH_RUN.finditer(message):
            text = run.group()
            start = text.find("/")
            while start >= 0:
                # Sliced only at a length some path has: each length once per run.
                if len(text) - start in self.lengths and text[start:] in self.plain:
                    named.add(text[start:])
                start = text.find("/", start + 1)
        named.update(p for p in self.other if _names(message, p))
        return named


def _names(message: str, path: str) -> bool:
    """Whether ``message`` names the prim ``path`` (not a longer path it prefixes)."""
    start = message.find(path)
    while start >= 0:
        end = start + len(path)
        if end == len(message) or not (message[end].isalnum() or message[end] in "_/"):
            return True
        start = message.find(path, end)
    return False


def _var(var: VarSpec) -> dict[str, Any]:
    return {
        "path": var.path,
        "name": var.name,
        "dataType": var.data_type,
        "sourceName": var.source_name,
        "sourceType": var.source_type,
        "namespacedSettings": dict(var.namespaced_settings),
    }


def _sources(sources: Mapping[str, Source]) -> dict[str, Any]:
    return {
        key: {
            "from": source.kind,
            "path": source.path,
            "layer": _display_path(source.layer) if source.layer else None,
            "line": source.line,
        }
        for key, source in sources.items()
    }


@functools.lru_cache(maxsize=64)
def _display_path(layer: str) -> str:
    # Resolving a path costs ~20 us and every value of a product names one of a
    # few layers. The working directory does not change while a document is built.
    return display_path(layer)


def _codes(findings: Iterable[Finding]) -> list[str]:
    return sorted({f.code for f in findings})


def _prim_path(path: str | None) -> str | None:
    # A prim name never holds ".": what follows the first one is the property.
    return path.split(".", 1)[0] if path else None


def _time(time: Time) -> float | str:
    return "default" if time is None else time


def _float(value: float) -> float | None:
    """A float32 value with the fewest digits that read back as the same float."""
    if not math.isfinite(value):
        return None
    for digits in range(1, 10):
        short = float(f"{value:.{digits}g}")
        if f32(short) == value:
            return short
    return value


def _floats(values: Iterable[float]) -> list[float | None]:
    return [_float(v) for v in values]


def _double(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _json_number(value: Any) -> Any:
    if isinstance(value, float):
        return _float(value)
    if isinstance(value, list):
        return [_json_number(v) for v in value]
    return value


__all__ = ["SCHEMA_VERSION", "file_document", "product_findings", "spec_document"]
