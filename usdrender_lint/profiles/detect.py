"""Which profile each render configuration is judged under (R2-5).

Explicit configuration wins. ``auto`` reads the evidence a renderer leaves in
a stage: the namespaces of the authored properties of a RenderSettings, its
products and their vars (``karma:``, ``ri:``, ``arnold:``, ``omni:rtx:``), the
API schemas applied to them, the scopes a renderer's application writes
(Kit's ``/Render/OmniverseKit``), what the settings' and products' ``camera``
targets (a prim type only one renderer defines, such as an ``OmniLidar``, or
a camera its application creates at run time, such as Kit's
``/OmniverseKit_Persp``) and the keys its application writes into the root
layer's customLayerData. Evidence of exactly one renderer picks its profile;
none, or several renderers' (a Houdini Render Settings LOP writes every
installed renderer's), leaves the schema alone: ``generic``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import field
from fnmatch import fnmatchcase
from functools import lru_cache
from typing import Any

from pxr import Sdf, Usd

from ..api import Context, schemas
from ..api.resolve import (
    RenderConfiguration,
    describe_prim_type,
    forwarded_targets,
    resolve_targets,
)
from ..model import Severity
from ..records import record
from . import AUTO, GENERIC, PROFILES, get_profile
from .model import Profile, ProfileChoice, judge

#: Renderer profiles in the order their evidence is reported.
_RENDERERS: tuple[Profile, ...] = tuple(p for p in PROFILES.values() if p is not GENERIC)


@record
class Assignment:
    """The profile of every scope (a RenderSettings, or a product no settings
    targets) and of the stage, and which scopes each render prim belongs to."""

    #: Scope key (the settings' or lone product's path) -> its choice.
    scopes: dict[Sdf.Path, ProfileChoice] = field(default_factory=dict)
    #: Prim path -> the scopes it belongs to (settings, products, vars, cameras).
    members: dict[Sdf.Path, list[Sdf.Path]] = field(default_factory=dict)
    stage: ProfileChoice = field(default_factory=lambda: ProfileChoice(GENERIC, ""))

    def choices_for(self, path: Sdf.Path | None) -> tuple[ProfileChoice, ...]:
        """The choices a finding at ``path`` is judged under (the stage's when
        the path belongs to no scope)."""
        if path is not None and path != Sdf.Path.emptyPath:
            keys = self.members.get(path.GetPrimPath())
            if keys:
                return tuple(dict.fromkeys(self.scopes[k] for k in keys))
        return (self.stage,)

    def for_scope(self, key: Sdf.Path) -> ProfileChoice:
        return self.scopes.get(key, self.stage)

    def judge(
        self, code: str, severity: Severity, rule_profile: str | None, at: Any
    ) -> tuple[ProfileChoice, Severity] | None:
        """The verdict on a finding of ``code`` anchored at ``at`` (a USD
        object, a path or None): see :func:`.model.judge`."""
        path = at.GetPath() if isinstance(at, Usd.Object) else at
        return judge(code, severity, rule_profile, self.choices_for(path))

    def present(self) -> set[str]:
        return {c.name for c in self.scopes.values()} | {self.stage.name}

    def _add(self, key: Sdf.Path, prims: Iterable[Usd.Prim | Sdf.Path]) -> None:
        for item in prims:
            path = item if isinstance(item, Sdf.Path) else item.GetPath()
            scopes = self.members.setdefault(path, [])
            if key not in scopes:
                scopes.append(key)


#: Evidence per renderer profile found on one prim, one phrase each.
PrimEvidence = dict[str, list[str]]

#: Every renderer's namespaces and scopes at once: most render prims hold
#: none of them, and one test of each says so before any renderer's own.
_NAMESPACES: tuple[str, ...] = tuple(ns for p in _RENDERERS for ns in p.namespaces)
_SCOPES: tuple[str, ...] = tuple(scope for p in _RENDERERS for scope in p.scopes)
_PRODUCT_TYPES = any(p.product_types for p in _RENDERERS)
#: Answers kept per camera path, camera type and productType (bounded: a language
#: server lints for hours).
_NAMES_KEPT = 4096


@lru_cache(maxsize=_NAMES_KEPT)
def _some_product_type(token: str) -> bool:
    return any(p.product_type(token) for p in _RENDERERS)


@lru_cache(maxsize=_NAMES_KEPT)
def _some_runtime_camera(path: str) -> bool:
    return any(p.runtime_camera(path) for p in _RENDERERS)


@lru_cache(maxsize=_NAMES_KEPT)
def _some_camera_type(type_name: str) -> bool:
    return any(p.camera_type(type_name) for p in _RENDERERS)


def _no_evidence(
    path: str,
    names: Sequence[str],
    applied: Sequence[str],
    product_type: str | None,
    cameras: Sequence[tuple[Sdf.Path, Usd.Prim | None]],
) -> bool:
    """True when no renderer can find evidence on the prim (the common case),
    decided with one test per kind of evidence for all renderers together."""
    if applied or (product_type and _some_product_type(product_type)):
        return False
    if any(path.startswith(scope) or path + "/" == scope for scope in _SCOPES):
        return False
    if _NAMESPACES and any(name.startswith(_NAMESPACES) for name in names):
        return False
    for target, camera in cameras:
        if _some_runtime_camera(str(target)):
            return False
        if camera is not None and _some_camera_type(camera.GetTypeName()):
            return False
    return True


def _prim_evidence(prim: Usd.Prim) -> PrimEvidence:
    """What on ``prim`` points at each renderer, read in one pass over its
    properties and API schemas (every renderer's namespaces at once)."""
    found: PrimEvidence = {}
    path = str(prim.GetPath())
    names = prim.GetAuthoredPropertyNames()
    applied = prim.GetPrimTypeInfo().GetAppliedAPISchemas()
    is_product = prim.IsA(schemas.RenderProduct)
    # The settings' and products' camera targets, read once for every renderer.
    cameras = _camera_targets(prim) if prim.IsA(schemas.RenderSettingsBase) else ()
    product_type = None
    if _PRODUCT_TYPES and is_product:
        product_type = str(prim.GetAttribute("productType").Get() or "")
    if _no_evidence(path, names, applied, product_type, cameras):
        return found
    for profile in _RENDERERS:
        phrases = []
        if any(path.startswith(scope) or path + "/" == scope for scope in profile.scopes):
            phrases.append(f"the prim <{path}> in {profile.scopes[0].rstrip('/')}")
        if profile.namespaces:
            phrases.extend(
                f"the property <{path}.{name}>"
                for name in names
                if name.startswith(profile.namespaces)
            )
        for schema in applied:
            if any(fnmatchcase(schema, pattern) for pattern in profile.api_schemas):
                phrases.append(f"the API schema {schema} on <{path}>")
        if profile.product_types and is_product:
            if product_type is None:
                product_type = str(prim.GetAttribute("productType").Get() or "")
            if product_type and profile.product_type(product_type):
                phrases.append(f"productType {product_type!r} of <{path}>")
        for target, camera in cameras:
            where = f"the camera target <{target}> of <{path}>"
            if profile.runtime_camera(str(target)):
                phrases.append(f"{where}, a camera the renderer's application creates")
            elif camera is not None and profile.camera_type(camera.GetTypeName()):
                phrases.append(f"{where}, {describe_prim_type(camera)}")
        if phrases:
            found[profile.name] = phrases
    return found


def _camera_targets(prim: Usd.Prim) -> list[tuple[Sdf.Path, Usd.Prim | None]]:
    """A settings or product prim's camera targets and the typed prims there."""
    stage = prim.GetStage()
    found: list[tuple[Sdf.Path, Usd.Prim | None]] = []
    for target in forwarded_targets(prim.GetRelationship("camera")):
        camera = stage.GetPrimAtPath(target) if target.IsPrimPath() else None
        found.append((target, camera if camera and camera.GetTypeName() else None))
    return found


def layer_data_evidence(stage: Usd.Stage | None) -> PrimEvidence:
    """The keys of the root layer's customLayerData (nested dictionaries'
    keys joined with ":", ``cameraSettings:boundCamera``) that a renderer's
    application writes, per renderer."""
    if stage is None:
        return {}
    keys: list[str] = []
    pending: list[tuple[str, dict]] = [("", dict(stage.GetRootLayer().customLayerData))]
    while pending:
        prefix, data = pending.pop()
        for key, value in data.items():
            keys.append(prefix + key)
            if isinstance(value, dict):
                pending.append((f"{prefix}{key}:", value))
    found: PrimEvidence = {}
    for profile in _RENDERERS:
        phrases = [
            f"the root layer's customLayerData {key}" for key in keys if profile.layer_datum(key)
        ]
        if phrases:
            found[profile.name] = phrases
    return found


def infer(
    prims: Sequence[Usd.Prim],
    memo: dict[Sdf.Path, PrimEvidence] | None = None,
    layer_data: PrimEvidence | None = None,
) -> ProfileChoice:
    """The ``auto`` choice for the render prims of one scope. ``memo`` keeps
    each prim's evidence across the scopes that share it (vars, products);
    ``layer_data`` is the stage's customLayerData evidence (default: read from
    the prims' stage)."""
    memo = {} if memo is None else memo
    if layer_data is None:
        layer_data = layer_data_evidence(prims[0].GetStage() if prims else None)
    hits: dict[str, list[str]] = {}
    for prim in prims:
        key = prim.GetPath()
        found = memo.get(key)
        if found is None:
            found = memo[key] = _prim_evidence(prim)
        for name, phrases in found.items():
            hits.setdefault(name, []).extend(phrases)
    for name, phrases in layer_data.items():
        hits.setdefault(name, []).extend(phrases)
    # Reported in the renderers' order, as each renderer's own evidence is.
    hits = {p.name: hits[p.name] for p in _RENDERERS if p.name in hits}
    if len(hits) == 1:
        name, evidence = next(iter(hits.items()))
        more = f" and {len(evidence) - 1} more" if len(evidence) > 1 else ""
        return ProfileChoice(PROFILES[name], f"auto: {evidence[0]}{more}")
    if not hits:
        return ProfileChoice(
            GENERIC,
            "auto: no renderer's properties, API schemas, scopes, camera targets or layer "
            "data on these render prims",
        )
    counts = ", ".join(f"{name}: {len(e)}" for name, e in hits.items())
    return ProfileChoice(
        GENERIC,
        f"auto: evidence of several renderers ({counts}), so the schema alone; "
        "pin one with profile = NAME or --profile",
    )


def _vars_of(product: Usd.Prim) -> list[Usd.Prim]:
    return [
        t.prim
        for t in resolve_targets(product.GetRelationship("orderedVars"))
        if t.ok and t.prim is not None and t.prim.IsA(schemas.RenderVar)
    ]


def _camera_paths(prims: Iterable[Usd.Prim]) -> list[Sdf.Path]:
    found: list[Sdf.Path] = []
    for prim in prims:
        for path in forwarded_targets(prim.GetRelationship("camera")):
            found.append(path.GetPrimPath())
    return found


def _connected(prim: Usd.Prim) -> list[Sdf.Path]:
    """Prims the settings' attributes connect to (hdPrman's render terminals)."""
    found: list[Sdf.Path] = []
    for attr in prim.GetAuthoredAttributes():  # a connection is always authored
        if attr.HasAuthoredConnections():
            found.extend(p.GetPrimPath() for p in attr.GetConnections())
    return found


def assign(
    configurations: Sequence[RenderConfiguration],
    lone_products: Sequence[Usd.Prim],
    passes: Sequence[Usd.Prim],
    setting: str = AUTO,
    reason: str = "",
    render_prims: Sequence[Usd.Prim] = (),
) -> Assignment:
    """Decide the profile of every scope. ``setting`` is a profile name or
    ``auto``; ``reason`` says where an explicit one was configured."""
    assignment = Assignment()
    memo: dict[Sdf.Path, PrimEvidence] = {}
    explicit = None if setting == AUTO else ProfileChoice(get_profile(setting), reason)
    prims = [*lone_products, *render_prims]
    layer_data = {} if explicit else layer_data_evidence(_stage_of(configurations, prims))
    by_settings: dict[Sdf.Path, list[RenderConfiguration]] = {}
    for config in configurations:
        if config.settings is not None:  # products on their own: below (R2-4)
            by_settings.setdefault(config.settings.GetPath(), []).append(config)
    for key, configs in by_settings.items():
        settings = configs[0].settings
        assert settings is not None
        products = [c.product for c in configs if c.product is not None]
        prims = [settings, *products, *(v for p in products for v in _vars_of(p))]
        assignment.scopes[key] = explicit or infer(prims, memo, layer_data)
        assignment._add(key, prims)
        assignment._add(key, _camera_paths([settings, *products]))
        assignment._add(key, _connected(settings))
    for product in lone_products:
        key = product.GetPath()
        prims = [product, *_vars_of(product)]
        assignment.scopes[key] = explicit or infer(prims, memo, layer_data)
        assignment._add(key, prims)
        assignment._add(key, _camera_paths([product]))
    for render_pass in passes:
        for path in forwarded_targets(render_pass.GetRelationship("renderSource")):
            if path in assignment.scopes:
                assignment._add(path, [render_pass])
    assignment.stage = explicit or _stage_choice(assignment, render_prims, memo, layer_data)
    return assignment


def _stage_of(
    configurations: Sequence[RenderConfiguration], render_prims: Sequence[Usd.Prim]
) -> Usd.Stage | None:
    for config in configurations:
        return config.owner.GetStage()
    return render_prims[0].GetStage() if render_prims else None


def _stage_choice(
    assignment: Assignment,
    render_prims: Sequence[Usd.Prim],
    memo: dict[Sdf.Path, PrimEvidence],
    layer_data: PrimEvidence,
) -> ProfileChoice:
    choices = list(dict.fromkeys(assignment.scopes.values()))
    names = {c.name for c in choices}
    if len(names) == 1:
        return choices[0]
    if not names:
        # No configuration (only vars or passes): the render prims' own evidence.
        return infer(render_prims, memo, layer_data)
    return ProfileChoice(
        GENERIC,
        "auto: the stage's configurations use several profiles "
        f"({', '.join(sorted(names))}); findings outside them use the schema alone",
    )


def _auto(file: str) -> tuple[str, str]:
    return AUTO, ""


class Profiler:
    """What the engine calls once per lint to decide the profiles: ``choose``
    gives a linted file's configured profile (a name or ``auto``) and where it
    was configured (default: ``auto`` for every file)."""

    def __init__(self, choose: Callable[[str], tuple[str, str]] | None = None) -> None:
        self.choose = choose or _auto

    def __call__(self, ctx: Context) -> Assignment:
        setting, reason = self.choose(ctx.file)
        return assign(
            ctx.configurations,
            ctx.untargeted_products,
            ctx.prims_of(schemas.RenderPass),
            setting,
            reason,
            [p for prims in ctx.render_prims.values() for p in prims],
        )
