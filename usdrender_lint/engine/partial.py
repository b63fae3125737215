"""The engine's fast path: compose only the part of a stage the rules read.

A render-settings linter needs the render prims, what they target and their
ancestors, not the whole composed scene, and composing a production shot costs
far more than reading its layers. So the engine first opens the stage with a
population mask (``Usd.StagePopulationMask``) holding:

- every prim spec of the root layer stack whose type the rules want (the render
  types, any type a rule lists in ``prim_types``, and unregistered type names),
  every prim carrying a ``usdrender_lint`` customData suppression, ``/Render``,
  and the prim ``renderSettingsPrimPath`` names;
- expanded along every relationship and attribute connection
  (``Usd.Stage.ExpandPopulationMask``: cameras, products, vars, passes,
  collection includes/excludes, forwarding) and along the collections that
  ``membershipExpression`` values reference (``%/path:name``), until nothing
  new is added.

Payloads are loaded only inside the mask. Prims outside the mask are never
composed, so the layers they alone use are never read by composition.

The mask is exact only when no wanted prim can appear anywhere else. That is
proven from the layers' specs, which are read (not composed) once: every layer
the stage can reach through sublayers, references and payloads is scanned,
and the fast path gives up (returns None: the engine composes everything) when

- a layer outside the root layer stack holds a wanted spec or suppression
  (a render prim brought in by a reference or payload: its stage path is not
  known without composing), or ``renderSettingsPrimPath`` (rules read every
  used layer's metadata);
- a wanted spec could be copied elsewhere by an arc whose mapping we do not
  follow: an inherit or specialize arc from outside the root layer stack
  (implied inheritance) to a class named like one of the spec's ancestors,
  relocates, or an internal reference to the default prim;
- a value clip layer may author ``renderSettingsPrimPath`` (ST007 reads the
  metadata of every used layer, and clip layers are used only where their
  prims are composed);
- a layer outside the root layer stack has a missing sublayer or sublayers
  that form a cycle (USD reports that at </>, but only when it composes a prim
  referencing the layer);
- an asset path uses expression variables, a layer cannot be read, or any
  error is posted on the way.

Arcs inside the root layer stack (inherits, specializes, internal references
and payloads) are followed: the spec's path is mapped from the arc's source to
its site and added to the mask. A rule that needs more than the mask (a walk
over the whole scene) calls ``Context.require_full_stage()`` and the engine
lints the file again, fully composed.
"""

from __future__ import annotations

import glob
import os
import re
from collections import Counter
from collections.abc import Callable, Collection, Iterable
from dataclasses import field
from itertools import filterfalse

from pxr import Ar, Sdf, Tf, Usd

from ..layers.crate import crate_spec_problem
from ..layers.files import layer_identifier, layer_real_path
from ..model import IGNORE_KEY
from ..paths import display_path, usd_path
from ..records import record
from . import layer_words
from .stage import arc_file_problem, arcs_problem, corruption
from .walks import names_an_empty_variant

#: The convention's render scope, always composed (rules look under it).
RENDER_SCOPE = Sdf.Path("/Render")
#: The customData dictionary holding the linter's suppressions (suppress.py).
IGNORE_DICTIONARY = IGNORE_KEY.partition(":")[0]
SETTINGS_PATH_KEY = "renderSettingsPrimPath"
#: Rounds of mask expansion before giving up (each adds what the last reached).
MAX_ROUNDS = 16
#: Paths the root layer stack's arcs may copy the wanted specs to before the
#: fast path gives up (cyclic arcs copy them without end).
MAX_COPIES = 50_000
#: When every layer is in the root layer stack, USD composes the stage about
#: as fast as Python can scan its specs: compose it all (same findings).
FLAT_STAGES_COMPOSE_FULLY = True
#: Scanning a spec costs a few times what composing it does, so the fast path
#: pays only when a full composition would compose several times the specs it
#: scans (layers referenced many times); below that, compose everything.
PAYOFF = 3
#: Scans smaller than this are cheap whatever the payoff.
MIN_SCAN = 50_000

_ARC_KEYS = frozenset({"inheritPaths", "specializes", "references", "payload"})
#: The fields through which a layer stack reaches other layers.
_EXTERNAL_ARC_WORDS = ("references", "payload")
#: The words that make a layer's spec fields worth listing (_scan).
_KEYED_WORDS = (*sorted(_ARC_KEYS), "relocates", "clips", IGNORE_DICTIONARY)


class NotProvable(Exception):
    """The fast path cannot show its mask is complete; compose everything."""


class CorruptLayer(NotProvable):
    """USD finds a layer's specs unreadable: reading them (a property stack,
    a spec handle) can crash the process, so no rule may run on the file."""


@record
class PartialStage:
    """A stage composed only within ``stage.GetPopulationMask()``, or None
    with the ``reason`` the whole stage must be composed instead."""

    stage: Usd.Stage | None
    #: Every layer read so far, kept open so that a full composition after
    #: this one does not read them again.
    layers: list[Sdf.Layer] = field(default_factory=list)
    reason: str | None = None
    #: (layer, asset path) of the arcs of ``layers`` whose layer does not exist.
    missing: list[tuple[Sdf.Layer, str]] = field(default_factory=list)
    #: The masked stage when the fast path gave up after composing it: it holds
    #: the root layer stack's layers (``layers`` holds only weak handles to them).
    held: Usd.Stage | None = field(default=None, repr=False)
    #: Why the file is corrupt (a layer's specs USD cannot read), or None.
    corrupt: str | None = None
    #: Identifiers of the crates whose specs were walked safely (no need to
    #: check them again before a full composition's rules run).
    checked: frozenset[str] = frozenset()


@record
class _LayerScan:
    """What a layer's prim specs hold that decides the mask."""

    #: Paths (variant selections stripped) of wanted specs and suppressions.
    wanted: set[Sdf.Path] = field(default_factory=set)
    #: (site, source) of inherits, specializes, internal references/payloads.
    arcs: list[tuple[Sdf.Path, Sdf.Path]] = field(default_factory=list)
    #: Names of the prims that inherit/specialize arcs point at.
    class_names: set[str] = field(default_factory=set)
    #: Asset paths of the references and payloads to other layers, per arc.
    external: list[str] = field(default_factory=list)
    #: Asset paths of the value clip layers (and manifests) its specs name.
    clips: list[str] = field(default_factory=list)
    #: Specs (prims and properties) the layer holds.
    specs: int = 0


def open_partial(path: str, wants_type: Callable[[str], bool]) -> PartialStage:
    """Open ``path`` composed only where the rules look; the result's stage is
    None when that cannot be proven to give the same findings as a full
    composition, or would not be faster.

    ``wants_type(type_name)`` is True for the prim type names the rules want
    to see (the engine's dispatch table decides)."""
    if FLAT_STAGES_COMPOSE_FULLY and layer_words.without_external_arcs(path):
        # Decided from the file's bytes, before USD reads the layer (or walks its
        # specs for GetCompositionAssetDependencies): the full open reads it once.
        return PartialStage(None, [], "every layer is in the root layer stack")
    opening = _Opening(wants_type)
    with Tf.DiagnosticTrap() as trap:
        try:
            opening.compose(path, trap)
        except (NotProvable, Tf.ErrorException) as exc:
            reason = str(exc).strip() or type(exc).__name__
            return opening.result(reason, reason if isinstance(exc, CorruptLayer) else None)
        finally:
            trap.Clear()
    return opening.result()


class _Opening:
    """One fast-path open: what it has read so far, kept when it gives up."""

    def __init__(self, wants_type: Callable[[str], bool]) -> None:
        self.layers: list[Sdf.Layer] = []
        self.missing: list[tuple[Sdf.Layer, str]] = []
        self.stage: Usd.Stage | None = None
        self.specs = _Specs()
        self.scans = _Scans(self.specs, wants_type)

    def compose(self, path: str, trap: Tf.DiagnosticTrap) -> None:
        """Open the stage masked to what the rules read; raises NotProvable."""
        root = Sdf.Layer.FindOrOpen(usd_path(path))
        if root is None:
            raise NotProvable("USD cannot open the layer")
        self.layers = [root]
        self.specs.check(root)
        # The common small file: one layer, no arcs to others. Checked
        # before building any stage, which costs more than the check.
        if FLAT_STAGES_COMPOSE_FULLY and not root.GetCompositionAssetDependencies():
            raise NotProvable("every layer is in the root layer stack")
        # Composing the root layer stack reads the sublayers: check them first.
        problem = arcs_problem(root, usd_path(path), external=False)
        if problem is not None:
            raise CorruptLayer(problem)
        stage = Usd.Stage.OpenMasked(usd_path(path), Usd.StagePopulationMask(), Usd.Stage.LoadAll)
        self.stage = stage
        root_stack = stage.GetLayerStack(includeSessionLayers=True)
        if FLAT_STAGES_COMPOSE_FULLY and not any(
            layer_words.layers_may_hold(root_stack, word) for word in _EXTERNAL_ARC_WORDS
        ):
            # Sublayers only: known before any layer's specs are scanned.
            raise NotProvable("every layer is in the root layer stack")
        self.layers = _reachable_layers(stage, self.missing, self.scans)
        if trap.HasErrors():
            raise NotProvable("an error was posted while reading the layers")
        if FLAT_STAGES_COMPOSE_FULLY and len(self.layers) == len(root_stack):
            raise NotProvable("every layer is in the root layer stack")
        stage.SetPopulationMask(_initial_mask(stage, self.layers, self.scans))
        _expand(stage)
        if trap.HasErrors():
            raise NotProvable("an error was posted while composing")

    def result(self, reason: str | None = None, corrupt: str | None = None) -> PartialStage:
        """The masked stage, or (with the ``reason`` it gave up) none."""
        checked = self.specs.walked()
        if reason is None:
            return PartialStage(self.stage, self.layers, missing=self.missing, checked=checked)
        return PartialStage(
            None,
            self.layers,
            reason,
            self.missing,
            held=self.stage,
            corrupt=corrupt,
            checked=checked,
        )


# -- layers ---------------------------------------------------------------------------


def _reachable_layers(
    stage: Usd.Stage, missing: list[tuple[Sdf.Layer, str]], scans: _Scans
) -> list[Sdf.Layer]:
    """The root layer stack, then every layer reachable through sublayers,
    references and payloads (variants included), each once. The arcs whose
    layer does not exist are added to ``missing``.

    A layer's arcs are read from its scan, which the mask needs anyway: asking
    Sdf (``GetCompositionAssetDependencies``) walks every spec a second time."""
    layers = list(stage.GetLayerStack(includeSessionLayers=True))
    root_stack = {layer_identifier(layer) for layer in layers}
    seen = set(root_stack)
    #: Sublayer edges of the layers outside the root layer stack.
    sublayers: dict[str, list[str]] = {}
    with Ar.ResolverContextBinder(stage.GetPathResolverContext()):
        queue = list(layers)
        while queue:
            anchor = queue.pop()
            own = () if layer_identifier(anchor) in root_stack else set(anchor.subLayerPaths)
            asset_paths = (*anchor.subLayerPaths, *scans.of(anchor).external)
            for asset_path in dict.fromkeys(asset_paths):
                if "`" in asset_path:
                    raise NotProvable(f"expression variables in @{asset_path}@")
                problem = arc_file_problem(anchor, asset_path)
                if problem is not None:
                    raise CorruptLayer(problem)
                # A layer that is missing is missing from the full stage too.
                layer = Sdf.Layer.FindOrOpenRelativeToLayer(anchor, asset_path)
                sublayer = asset_path in own
                if layer is None:
                    if sublayer:
                        # USD reports it at the site </> when it composes the
                        # referencing prim, which the mask may leave out (ST002).
                        raise NotProvable(f"a sublayer of {layer_identifier(anchor)} is missing")
                    missing.append((anchor, asset_path))
                    continue
                if sublayer:
                    edges = sublayers.setdefault(layer_identifier(anchor), [])
                    edges.append(layer_identifier(layer))
                if layer_identifier(layer) not in seen:
                    seen.add(layer_identifier(layer))
                    layers.append(layer)
                    queue.append(layer)
        for anchor in layers:
            _check_clip_layers(anchor, scans.of(anchor).clips)
    if _has_cycle(sublayers):
        # Reported at </> too, and only where a referencing prim is composed.
        raise NotProvable("the sublayers of a layer outside the root layer stack form a cycle")
    return layers


def _check_clip_layers(anchor: Sdf.Layer, asset_paths: list[str]) -> None:
    """Raise NotProvable when a value clip layer may author
    ``renderSettingsPrimPath``: clip layers are used layers (ST007 reads
    their metadata), but only those of the prims a stage composes."""
    for asset_path in dict.fromkeys(asset_paths):
        if "`" in asset_path:
            raise NotProvable(f"expression variables in @{asset_path}@")
        identifier = Sdf.ComputeAssetPathRelativeToLayer(anchor, asset_path)
        if "#" in os.path.basename(asset_path):
            # A template (``cache.###.usd``): every file its frames may name.
            if not os.path.isabs(identifier):
                raise NotProvable(f"value clips from the template @{asset_path}@")
            folder, name = os.path.split(identifier)
            pattern = re.sub("#+", "*", glob.escape(name))
            files = glob.glob(os.path.join(glob.escape(folder), pattern))
        else:
            files = [str(Ar.GetResolver().Resolve(identifier))]
        # Read as bytes, not as layers: clips are often many large files.
        for file in filter(None, files):
            if layer_words.may_hold(file, (SETTINGS_PATH_KEY,)):
                raise NotProvable(f"the value clip layer {file} may author {SETTINGS_PATH_KEY}")


def _has_cycle(edges: dict[str, list[str]]) -> bool:
    """Whether the directed graph ``edges`` (node -> successors) has a cycle."""
    done: set[str] = set()
    for start in edges:
        if start in done:
            continue
        path = {start}
        stack = [(start, iter(edges.get(start, ())))]
        while stack:
            node, successors = stack[-1]
            nxt = next(successors, None)
            if nxt is None:
                stack.pop()
                path.discard(node)
                done.add(node)
            elif nxt in path:
                return True
            elif nxt not in done:
                path.add(nxt)
                stack.append((nxt, iter(edges.get(nxt, ()))))
    return False


class _Scans:
    """Each layer's :func:`_scan`, made once per fast-path open."""

    def __init__(self, specs: _Specs, wants_type: Callable[[str], bool]) -> None:
        self._specs = specs
        self._wants_type = wants_type
        self._scans: dict[str, _LayerScan] = {}

    def of(self, layer: Sdf.Layer) -> _LayerScan:
        found = self._scans.get(layer_identifier(layer))
        if found is None:
            found = _scan(layer, self._wants_type, self._specs.paths(layer))
            self._scans[layer_identifier(layer)] = found
        return found


class _Specs:
    """Each layer's spec paths, read once per fast-path open, and only from a
    layer that walking cannot crash.

    Sdf's recursive walks of a layer (``Traverse``, and the one behind
    ``GetCompositionAssetDependencies``) abort the process on names usd-core
    26.11 reads but cannot make paths of, where composing the stage merely
    posts an error or never looks: a variant named "" (the walks recurse
    without end or dereference an invalid variant set spec) and, in a corrupt
    crate, a prim named "" (an invalid prim spec). A layer holding either is
    left to the full composition (NotProvable), so the fast path survives
    whatever composing the stage survives. A crate whose specs USD cannot
    read (an invalid spec type: building a handle to that spec crashes) is
    CorruptLayer. :meth:`check` comes before any walk of a layer."""

    def __init__(self) -> None:
        self._paths: dict[str, list[Sdf.Path]] = {}
        self._checked: set[str] = set()

    def check(self, layer: Sdf.Layer) -> None:
        if layer_identifier(layer) in self._checked:
            return
        if names_an_empty_variant(layer):
            raise NotProvable(f'{layer_identifier(layer)} names a variant ""')
        if layer.GetFileFormat().formatId != "usda":
            # Traverse survives a crate's prim named "" and visits it as the
            # empty path (_traverse refuses it).
            self._paths[layer_identifier(layer)] = self._traverse(layer)
        self._checked.add(layer_identifier(layer))

    def walked(self) -> frozenset[str]:
        """The crates whose specs :meth:`check` walked without a problem."""
        return frozenset(self._paths)

    def paths(self, layer: Sdf.Layer) -> list[Sdf.Path]:
        """Every spec path of the layer, prims inside variants included."""
        self.check(layer)
        if layer.HasRelocates():
            raise NotProvable(f"{layer_identifier(layer)} has relocates")
        found = self._paths.get(layer_identifier(layer))
        if found is None:
            found = self._paths[layer_identifier(layer)] = self._traverse(layer)
        return found

    @staticmethod
    def _traverse(layer: Sdf.Layer) -> list[Sdf.Path]:
        # Sdf's own traversal, collected and filtered, is cheaper than walking
        # nameChildren from Python.
        paths: list[Sdf.Path] = []
        try:
            layer.Traverse(Sdf.Path.absoluteRootPath, paths.append)
        except Tf.ErrorException as exc:
            raise CorruptLayer(_unreadable_specs(layer, exc)) from exc
        if paths and not all(paths):  # an empty path: a prim named ""
            raise NotProvable(f"{layer_identifier(layer)} holds a prim with no name")
        return paths


def unsafe_to_walk(layer: Sdf.Layer) -> str | None:
    """Why Sdf's walks of ``layer`` could abort the process (see _Specs), or
    None: for another caller of ``GetCompositionAssetDependencies``."""
    try:
        _Specs().check(layer)
    except NotProvable as exc:
        return str(exc)
    return None


def crate_problem(layer: Sdf.Layer, *, walk: bool = False) -> str | None:
    """Why the crate ``layer``'s specs cannot be read safely (the file is
    corrupt), or None; None for any other layer. Its file's bytes say whether
    a spec's type is invalid (layers/crate.py: the crash a rule's read met);
    ``walk`` also walks every spec through Sdf, which finds whatever else USD
    cannot read in them but costs about as much as opening the layer (the
    retry after a crash; a crate inside a package, whose bytes are not read
    here). A crate naming a variant "" is not walked (walking it cannot be
    done safely; composing it can)."""
    if layer.anonymous or layer.GetFileFormat().formatId != "usdc":
        return None
    file = layer_real_path(layer)
    plain = bool(file) and os.path.isfile(file)
    why = crate_spec_problem(file) if plain else None
    if why is not None:
        return _specs_message(layer, why)
    if plain and not walk:
        return None
    with Tf.DiagnosticTrap() as trap:
        try:
            _Specs().check(layer)
        except CorruptLayer as exc:
            return str(exc)
        except NotProvable:
            return None
        finally:
            trap.Clear()
    return None


def _unreadable_specs(layer: Sdf.Layer, exc: Tf.ErrorException) -> str:
    known = corruption(exc, layer_real_path(layer) or layer_identifier(layer))
    if known is not None and "Corrupt asset" in known:
        return known  # as when a rule reads the value
    commentary = [str(getattr(arg, "commentary", "") or "") for arg in exc.args]
    # USD's "Invalid spec type N" quotes memory it did not initialise: no N.
    why = next((c.strip() for c in commentary if c.strip()), "an unknown error")
    why = "a spec of no valid type" if why.startswith("Invalid spec type") else why
    return _specs_message(layer, why)


def _specs_message(layer: Sdf.Layer, why: str) -> str:
    name = display_path(layer_real_path(layer) or layer_identifier(layer))
    return f"USD cannot read the specs of {name} ({why}); the file is corrupt"


def _is_prim_site(path: Sdf.Path) -> bool:
    return path.IsPrimPath() or path.IsPrimVariantSelectionPath()


#: The prim fields _scan asks a spec about, in the order it asks.
_SPEC_KEYS = (
    "references",
    "payload",
    "inheritPaths",
    "specializes",
    "customData",
    "relocates",
    "clips",
)
#: Above this many fields to ask about, one ListInfoKeys costs less than a
#: HasInfo per field (about 2.7 and 1 microseconds a prim, usd-core 26.11).
_MAX_HAS_INFO = 2


def _scan(layer: Sdf.Layer, wants_type: Callable[[str], bool], paths: list[Sdf.Path]) -> _LayerScan:
    """Record the layer's wanted specs and arcs (of ``paths``)."""
    scan = _LayerScan(specs=len(paths))
    get_spec = layer.GetPrimAtPath
    asked = _asked_keys(layer)
    list_keys = len(asked) > _MAX_HAS_INFO
    wanted: dict[str, bool] = {}
    # Most paths are properties: skipped by one C-level loop over them.
    for path in filterfalse(Sdf.Path.IsPropertyPath, paths):
        if not _is_prim_site(path):
            continue
        spec = get_spec(path)
        if not isinstance(spec, Sdf.PrimSpec):
            continue  # a variant set
        type_name = spec.typeName
        if type_name:
            want = wanted.get(type_name)
            if want is None:
                want = wanted[type_name] = wants_type(type_name)
            if want:
                scan.wanted.add(path.StripAllVariantSelections())
        if asked:
            keys = spec.ListInfoKeys() if list_keys else [k for k in asked if spec.HasInfo(k)]
            if keys:
                _scan_fields(layer, spec, scan, keys)
    return scan


def _asked_keys(layer: Sdf.Layer) -> tuple[str, ...]:
    """The prim fields (of _SPEC_KEYS) the layer's specs may hold. A layer
    whose file holds none of these words has no arc, relocates or suppression
    on any spec: its specs' fields need no listing (layer_words.py)."""
    words = (
        set(_KEYED_WORDS)
        if layer.anonymous or layer.dirty or not layer_real_path(layer)
        else layer_words.may_hold(layer_real_path(layer), _KEYED_WORDS)
    )
    if IGNORE_DICTIONARY in words:
        words.add("customData")
    return tuple(key for key in _SPEC_KEYS if key in words)


def _scan_fields(
    layer: Sdf.Layer, spec: Sdf.PrimSpec, scan: _LayerScan, keys: Collection[str]
) -> None:
    """Record what the prim spec's fields ``keys`` (those it holds) decide."""
    if "customData" in keys and IGNORE_DICTIONARY in spec.customData:
        scan.wanted.add(spec.path.StripAllVariantSelections())
    if "relocates" in keys:
        raise NotProvable(f"relocates on {spec.path} in {layer_identifier(layer)}")
    if "clips" in keys:
        _record_clips(spec, scan)
    if not _ARC_KEYS.isdisjoint(keys):
        _record_arcs(spec, scan, keys)


def _record_clips(spec: Sdf.PrimSpec, scan: _LayerScan) -> None:
    """Record the layers the spec's value clips read (each clip set's)."""
    for clip_set in dict(spec.GetInfo("clips")).values():
        if not isinstance(clip_set, dict):
            continue
        assets = [*clip_set.get("assetPaths", ()), clip_set.get("manifestAssetPath")]
        scan.clips.extend(a.path for a in assets if isinstance(a, Sdf.AssetPath) and a.path)
        template = clip_set.get("templateAssetPath")
        if isinstance(template, str) and template:
            scan.clips.append(template)


def _record_arcs(spec: Sdf.PrimSpec, scan: _LayerScan, keys: Collection[str]) -> None:
    """Record the arcs of the fields ``keys`` names (each list read only if present)."""
    site = spec.path.StripAllVariantSelections()
    classes = (
        *(spec.inheritPathList.GetAddedOrExplicitItems() if "inheritPaths" in keys else ()),
        *(spec.specializesList.GetAddedOrExplicitItems() if "specializes" in keys else ()),
    )
    for target in classes:
        target = target.MakeAbsolutePath(spec.path).StripAllVariantSelections()
        scan.arcs.append((site, target))
        scan.class_names.add(target.name)
    arcs = (
        *(spec.referenceList.GetAddedOrExplicitItems() if "references" in keys else ()),
        *(spec.payloadList.GetAddedOrExplicitItems() if "payload" in keys else ()),
    )
    for arc in arcs:
        if arc.assetPath:
            scan.external.append(arc.assetPath)
            continue
        if arc.primPath.isEmpty:
            raise NotProvable(f"internal arc to the default prim on {spec.path}")
        target = arc.primPath.MakeAbsolutePath(spec.path).StripAllVariantSelections()
        scan.arcs.append((site, target))


# -- the mask ---------------------------------------------------------------------------


def _initial_mask(
    stage: Usd.Stage, layers: list[Sdf.Layer], scans: _Scans
) -> Usd.StagePopulationMask:
    root_stack = {
        layer_identifier(layer) for layer in stage.GetLayerStack(includeSessionLayers=True)
    }
    foreign_classes: set[str] = set()
    root_scan = _LayerScan()
    weight = _Weights(layers, scans, root_stack)
    composed = 0
    for layer in layers:
        scan = scans.of(layer)
        if layer_identifier(layer) in root_stack:
            root_scan.wanted |= scan.wanted
            root_scan.arcs.extend(scan.arcs)
            composed += scan.specs + weight.of_arcs(layer, scan.external)
            continue
        if scan.wanted:
            raise NotProvable(f"{layer_identifier(layer)} brings in wanted prims through an arc")
        if layer.pseudoRoot.HasInfo(SETTINGS_PATH_KEY):
            raise NotProvable(f"{layer_identifier(layer)} authors {SETTINGS_PATH_KEY}")
        foreign_classes |= scan.class_names
    _check_payoff(composed, sum(scans.of(layer).specs for layer in layers))
    wanted = _follow_arcs(root_scan.wanted | {RENDER_SCOPE}, root_scan.arcs)
    for path in wanted:
        if any(prefix.name in foreign_classes for prefix in path.GetPrefixes()):
            raise NotProvable(f"{path} may be inherited from outside the root layer stack")
    settings_path = stage.GetMetadata(SETTINGS_PATH_KEY)
    if settings_path and Sdf.Path.IsValidPathString(settings_path):
        target = Sdf.Path(settings_path)
        if target.IsAbsolutePath() and target.IsPrimPath():
            wanted.add(target)
    return Usd.StagePopulationMask(sorted(wanted))


class _Weights:
    """How many specs referencing a layer once composes: its own and, per arc,
    those of the layers it references (a projection, not a count)."""

    def __init__(self, layers: list[Sdf.Layer], scans: _Scans, root_stack: set[str]) -> None:
        self._layers = {layer_identifier(layer): layer for layer in layers}
        self._scans = scans
        self._root_stack = root_stack
        self._weights: dict[str, int] = {}

    def of_arc(self, anchor: Sdf.Layer, asset_path: str) -> int:
        identifier = Sdf.ComputeAssetPathRelativeToLayer(anchor, asset_path)
        layer = self._layers.get(identifier)
        if layer is None or identifier in self._root_stack:
            return 0  # missing, or in the root layer stack (counted there)
        if identifier not in self._weights:
            self._weights[identifier] = 0  # a cycle adds nothing
            scan = self._scans.of(layer)
            self._weights[identifier] = scan.specs + self.of_arcs(layer, scan.external)
        return self._weights[identifier]

    def of_arcs(self, anchor: Sdf.Layer, asset_paths: list[str]) -> int:
        # A layout references a few assets thousands of times: each asset once.
        return sum(n * self.of_arc(anchor, a) for a, n in Counter(asset_paths).items())


def _check_payoff(composed: int, scanned: int) -> None:
    """Give up when a full composition would compose less than PAYOFF times
    the specs the fast path scanned (``composed`` counts a referenced layer's
    specs once per arc that brings them in)."""
    if scanned >= MIN_SCAN and composed < PAYOFF * scanned:
        raise NotProvable(
            f"composing everything (about {composed:.0f} specs) is cheaper than scanning "
            f"{scanned} specs"
        )


def _follow_arcs(wanted: set[Sdf.Path], arcs: list[tuple[Sdf.Path, Sdf.Path]]) -> set[Sdf.Path]:
    """Add where the root layer stack's own arcs copy the wanted specs to.

    Each round maps only the paths the last one added (the others' copies are
    known). Arcs that nest a prim's copies inside it (a composition cycle, an
    error USD does not compose) would add copies of copies without end, and
    their number grows exponentially with the rounds: past MAX_COPIES the
    fast path gives up instead."""
    too_often = "arcs in the root layer stack copy the render prims too often"
    frontier = set(wanted)
    for _ in range(MAX_ROUNDS):
        added: set[Sdf.Path] = set()
        for path in frontier:
            for site, source in arcs:
                if path.HasPrefix(source):
                    added.add(path.ReplacePrefix(source, site))
            if len(added) > MAX_COPIES:
                raise NotProvable(too_often)
        added -= wanted
        if not added:
            return wanted
        wanted |= added
        if len(wanted) > MAX_COPIES:
            raise NotProvable(too_often)
        frontier = added
    raise NotProvable(too_often)


def _expand(stage: Usd.Stage) -> None:
    """Grow the mask along relationships, connections and the collections
    that membership expressions reference, until it stops growing."""
    for _ in range(MAX_ROUNDS):
        stage.ExpandPopulationMask()
        mask = stage.GetPopulationMask()
        missing = [p for p in _expression_references(stage) if not mask.Includes(p)]
        if not missing:
            return
        stage.SetPopulationMask(mask.GetUnion(Usd.StagePopulationMask(missing)))
    raise NotProvable("the population mask kept growing")


def _expression_references(stage: Usd.Stage) -> Iterable[Sdf.Path]:
    """Prims owning the collections that composed membership expressions name."""
    for prim in stage.TraverseAll():
        for collection in Usd.CollectionAPI.GetAllCollections(prim):
            attr = collection.GetMembershipExpressionAttr()
            expression = attr.Get() if attr and attr.HasAuthoredValue() else None
            if not isinstance(expression, Sdf.PathExpression) or expression.IsEmpty():
                continue
            references: list = []
            expression.Walk(lambda *_: None, references.append, lambda *_: None)
            for reference in references:
                if not reference.path.isEmpty:
                    yield reference.path.MakeAbsolutePath(prim.GetPath())
