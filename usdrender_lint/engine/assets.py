"""What a lint read, and which files the asset paths it met name: what the
result cache keys a lint's result on (running/result_cache.py).

Every asset path a layer can hold has an answer here and none raises: an
internal arc names no layer; a path to a file names that file; a search path
(``assets/chair.usda``) is looked up by the resolver, and what it finds is
recorded; a path whose file depends on more than the path and the files on
disk (expression variables, another resolver's URI, an anonymous layer, a path
Sdf cannot anchor) is :class:`Unkeyable`, which makes the result uncacheable.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable
from dataclasses import field

from pxr import Sdf, Tf, Usd

from ..layers.files import layer_identifier, layer_real_path
from ..records import record
from . import partial

#: A URI scheme or the anonymous layers' prefix (``omniverse:``, ``https:``,
#: ``anon:``); two characters at least, so that ``C:`` stays a drive.
#: (Pattern text: re compiles it at first use, not at every start-up.)
_SCHEME = r"[A-Za-z][A-Za-z0-9+.\-]+:"


class Unkeyable(Exception):
    """The layer an asset path names is not known from the path and the files
    on disk (the message says why)."""


def arc_target(anchor: Sdf.Layer, asset_path: str) -> str | None:
    """The identifier of the layer ``asset_path`` names, anchored at ``anchor``
    (a file path, perhaps a package member ``a.usdz[b.usda]``, or a search path
    the resolver looks up), or None when it names no layer: an internal
    reference or payload (``references = </prim>``, whose asset path Sdf gives
    as ``''``). Raises :class:`Unkeyable`."""
    if not asset_path:
        return None
    if "`" in asset_path:
        raise Unkeyable(f"@{asset_path}@ uses expression variables")
    if re.match(_SCHEME, asset_path):
        raise Unkeyable(f"@{asset_path}@ is resolved by a resolver other than the file system")
    # File format arguments choose how the file is read, not which file it is.
    asset_path = asset_path.partition(":SDF_FORMAT_ARGS:")[0]
    try:
        return Sdf.ComputeAssetPathRelativeToLayer(anchor, asset_path)
    except Tf.ErrorException as exc:
        detail = " ".join(str(exc).split())
        raise Unkeyable(f"@{asset_path}@ cannot be anchored: {detail}") from None


def is_search_path(identifier: str) -> bool:
    """True for an identifier the resolver looks up (neither absolute nor
    anchored), such as ``assets/chair.usda``."""
    return not os.path.isabs(identifier.partition("[")[0])


@record(frozen=True)
class ClipTemplate:
    """The files a value clip template (``templateAssetPath``) can match: the
    names in ``folder`` that ``pattern`` matches, and those it matched."""

    folder: str
    pattern: str
    matched: tuple[str, ...]


def clip_template(anchor: Sdf.Layer, template: str) -> ClipTemplate:
    """What ``template`` (``./clips/shot.###.usd``, anchored at the layer that
    authored it) can match, read from the folder now. USD derives one asset
    path per time (``%0Nd`` of the time, per ``#`` group) and keeps those that
    resolve (usd/clipSetDefinition.cpp, _DeriveClipInfo): any file the pattern
    matches may become a clip. Raises :class:`Unkeyable`."""
    path = arc_target(anchor, template)
    if path is None or is_search_path(path) or "[" in path:
        raise Unkeyable(f"the clip template @{template}@ is not a folder's files")
    folder, basename = os.path.split(path)
    groups = []
    for token in (t for t in basename.split(".") if t):  # TfStringTokenize drops empty ones
        groups.append(r"-?[0-9]+" if set(token) == {"#"} else re.escape(token))
    pattern = r"\.".join(groups)
    try:
        names = os.listdir(folder)
    except OSError:
        names = []
    matched = tuple(sorted(n for n in names if re.fullmatch(pattern, n)))
    return ClipTemplate(folder, pattern, matched)


@record
class Reads:
    """What linting one file read, for a cache that must know when the findings
    go stale (running/result_cache.py): every layer a linted stage used or the
    fast path opened (value clips included), the layers arcs name that do not
    exist, the search paths arcs name, the files whose existence a rule checked
    and the folders clip templates match files in. ``complete`` is False when
    that is not known: an asset path is :class:`Unkeyable`, or a layer could
    not be walked safely. (A lint that stopped part way says so itself:
    ``LintRun.completed``.)"""

    #: (identifier, real path, anonymous, has unsaved edits) of each layer read.
    layers: list[tuple[str, str, bool, bool]] = field(default_factory=list)
    #: Identifiers of layers an arc names, which may not exist (yet): file paths.
    targets: list[str] = field(default_factory=list)
    #: Search paths arcs name that the resolver did not find.
    searches: list[str] = field(default_factory=list)
    #: Files (and search paths) whose existence, not content, a rule checked.
    assets: list[str] = field(default_factory=list)
    #: Value clip templates and the files they matched.
    clip_templates: list[ClipTemplate] = field(default_factory=list)
    #: The stage's resolver context (its repr): what resolved the search paths.
    context: str = ""
    complete: bool = True

    def merge(self, other: Reads) -> None:
        """Add what another lint read (--variants lints a stage once per combination)."""
        self.layers.extend(other.layers)
        self.targets.extend(other.targets)
        self.searches.extend(other.searches)
        self.assets.extend(other.assets)
        self.clip_templates.extend(other.clip_templates)
        self.context = other.context or self.context
        self.complete = self.complete and other.complete

    def add_layers(self, layers: Iterable[Sdf.Layer]) -> None:
        self.layers.extend(
            (layer_identifier(x), layer_real_path(x), x.anonymous, x.dirty) for x in layers
        )

    def add_arc_targets(self, layers: Iterable[Sdf.Layer]) -> None:
        """The sublayers, references and payloads ``layers`` name, found or not."""
        for layer in layers:
            if layer.anonymous:
                continue
            if partial.unsafe_to_walk(layer) is not None:
                self.complete = False  # walking it could abort the process
                continue
            for asset in layer.GetCompositionAssetDependencies():
                self.add_target(layer, asset)

    def add_target(self, anchor: Sdf.Layer, asset_path: str) -> None:
        """The layer an arc of ``anchor`` names with ``asset_path`` (which may
        not exist); an internal arc names none."""
        try:
            identifier = arc_target(anchor, asset_path)
        except Unkeyable:
            self.complete = False  # which file it names is not known from its path
            return
        if identifier is None:
            return
        if not is_search_path(identifier):
            self.targets.append(identifier)
            return
        # Looked up by the resolver: next to the layer first (Sdf anchors a search
        # path there when that file exists), then where the resolver looks.
        self.searches.append(identifier)
        if layer_real_path(anchor):
            self.targets.append(os.path.join(os.path.dirname(anchor.realPath), identifier))

    def add_asset(self, anchor: Sdf.Layer | None, value: Sdf.AssetPath) -> None:
        """An asset-valued attribute's value whose existence a rule checked:
        the file it resolved to, or where it would be found."""
        if value.resolvedPath:
            self.assets.append(value.resolvedPath)
            return
        authored = value.evaluatedPath or value.authoredPath
        if anchor is None or anchor.anonymous:
            self.complete = False
            return
        try:
            identifier = arc_target(anchor, authored)
        except Unkeyable:
            self.complete = False
            return
        if identifier is None:
            return
        self.assets.append(identifier)
        if is_search_path(identifier) and layer_real_path(anchor):
            self.assets.append(os.path.join(os.path.dirname(anchor.realPath), identifier))

    def add_clips(self, stage: Usd.Stage) -> None:
        """Every value clip and clip manifest the stage's prims name (a clip
        USD has not opened yet, because no rule read its times, still decides
        what a rule would read), and the files a clip template can match."""
        prims = Usd.PrimRange.Stage(stage, Usd.TraverseInstanceProxies(Usd.PrimAllPrimsPredicate))
        for prim in prims:
            if not prim.HasAuthoredMetadata("clips"):
                continue
            clips = Usd.ClipsAPI(prim)
            for clip_set in prim.GetMetadata("clips") or {}:
                assets = list(clips.ComputeClipAssetPaths(clip_set))
                manifest = clips.GetClipManifestAssetPath(clip_set)
                if manifest is not None and manifest.path:
                    assets.append(manifest)
                for asset in assets:
                    if asset.resolvedPath:
                        self.targets.append(asset.resolvedPath)
                    else:
                        self.complete = False  # a clip that is missing: where would it be?
                template = clips.GetClipTemplateAssetPath(clip_set)
                if template:
                    self._add_template(prim, clip_set, template)

    def _add_template(self, prim: Usd.Prim, clip_set: str, template: str) -> None:
        # The template is anchored at the layer of the strongest opinion about it.
        for spec in prim.GetPrimStack():
            info = spec.GetInfo("clips") if spec.HasInfo("clips") else None
            if info and template == (info.get(clip_set) or {}).get("templateAssetPath"):
                try:
                    self.clip_templates.append(clip_template(spec.layer, template))
                except Unkeyable:
                    self.complete = False
                return
        self.complete = False  # authored where the prim stack does not show
