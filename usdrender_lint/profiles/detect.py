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
from itertools import repeat
from typing import Any

from pxr import Sdf, Usd

from ..api import Context, schemas
from ..api.resolve import (
    PrimValues,
    RenderConfiguration,
    Target,
    describe_prim_type,
    prim_values,
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
    #: Prim path -> the scopes it belongs to (settings, products, vars, cameras);
    #: left empty when every scope is judged as the stage is (then no finding
    #: needs to know its scopes).
    members: dict[Sdf.Path, list[Sdf.Path]] = field(default_factory=dict)
    stage: ProfileChoice = field(default_factory=lambda: ProfileChoice(GENERIC, ""))

    def choices_for(self, path: Sdf.Path | None) -> tuple[ProfileChoice, ...]:
        """The choices a finding at ``path`` is judged under (the stage's when
        the path belongs to no scope)."""
        if not self.members:  # every scope is judged as the stage is
            return (self.stage,)
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
        if not self.members:
            return judge(code, severity, rule_profile, (self.stage,))
        path = at.GetPath() if isinstance(at, Usd.Object) else at
        return judge(code, severity, rule_profile, self.choices_for(path))

    def present(self) -> set[str]:
        if not self.scopes:
            return {self.stage.name}
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


def _scope_root(scope: str) -> Sdf.Path:
    """The prim at or under which every prim whose path text starts with
    ``scope`` lies (or ``scope`` with its last "/"): its last "/" ends a prim
    path; the absolute root when that is no absolute prim path."""
    head = scope[: scope.rfind("/")]
    if head.startswith("/") and Sdf.Path.IsValidPathString(head):
        path = Sdf.Path(head)
        if path.IsAbsoluteRootOrPrimPath():
            return path
    return Sdf.Path.absoluteRootPath


_SCOPE_ROOTS: tuple[Sdf.Path, ...] = tuple(dict.fromkeys(_scope_root(s) for s in _SCOPES))
#: Answers kept per camera path, camera type and productType (bounded: a language
#: server lints for hours).
_NAMES_KEPT = 4096

#: The auto choice of render prims that hold no renderer's evidence (the common
#: case), made once: a choice is frozen.
_NO_EVIDENCE = ProfileChoice(
    GENERIC,
    "auto: no renderer's properties, API schemas, scopes, camera targets or layer "
    "data on these render prims",
)


@lru_cache(maxsize=_NAMES_KEPT)
def _some_product_type(token: str) -> bool:
    return any(p.product_type(token) for p in _RENDERERS)


@lru_cache(maxsize=_NAMES_KEPT)
def _some_runtime_camera(path: Sdf.Path) -> bool:
    # Keyed by the path: hashing one is cheaper than spelling it.
    return any(p.runtime_camera(str(path)) for p in _RENDERERS)


@lru_cache(maxsize=_NAMES_KEPT)
def _some_camera_type(type_name: str) -> bool:
    return any(p.camera_type(type_name) for p in _RENDERERS)


def _product_type(values: PrimValues, names: Sequence[str]) -> str:
    """A product's productType as ``Get()`` reads it: the authored value, else
    (no layer authors the name) its definition's fallback, without a read."""
    if "productType" not in names:
        return str(values.fallback("productType") or "")  # read once per definition
    # A well-typed value is the one the rules read (PR003); any other opinion
    # (a mismatched type, a block) is what Get() returns of it.
    if values.has_value("productType"):
        return str(values.authored("productType") or "")
    return str(values.attribute("productType").Get() or "")


#: What a render prim is, which decides what on it can be evidence: the
#: settings' and products' camera targets (both are RenderSettingsBase), a
#: product's productType.
_SETTINGS, _PRODUCT, _OTHER = "settings", "product", "other"


def _kind(prim: Usd.Prim) -> str:
    """The kind of a render prim the caller knows nothing of."""
    if prim.IsA(schemas.RenderProduct):
        return _PRODUCT
    return _SETTINGS if prim.IsA(schemas.RenderSettingsBase) else _OTHER


#: A camera target of a settings or product prim, the typed prim there (None
#: when there is none) and its type name ("" then).
Camera = tuple[Sdf.Path, Usd.Prim | None, str]


def _usable_var(target: Target) -> PrimValues | None:
    prim = target.prim
    if not target.ok or prim is None:
        return None
    values = prim_values(prim)
    return values if values.is_a(schemas.RenderVar) else None


def _camera(target: Target) -> Camera:
    """A camera target and the typed prim there (the resolution the rules share)."""
    camera = target.prim if target.path.IsPrimPath() else None
    type_name = Usd.Prim.GetTypeName(camera) if camera else ""  # unbound: valid, checked
    return (target.path, camera, type_name) if type_name else (target.path, None, "")


class _Facts:
    """A render prim of a scope: its PrimValues, the evidence on it (phrases
    per renderer) and, for a product, its usable RenderVars (None until asked)."""

    __slots__ = ("values", "kind", "_path", "vars", "evidence")

    def __init__(self, values: PrimValues, kind: str, scan: _Scan) -> None:
        self.values = values
        self.kind = kind
        self._path: Sdf.Path | None = None
        self.vars: list[_Facts] | None = None
        self.evidence: PrimEvidence = {} if scan.plain(values, kind) else self._found(scan)

    @property
    def path(self) -> Sdf.Path:
        path = self._path
        if path is None:
            path = self._path = self.values.prim.GetPath()
        return path

    @property
    def text(self) -> str:
        return str(self.path)

    def _found(self, scan: _Scan) -> PrimEvidence:
        names, applied, product_type, cameras = scan.reads(self.values, self.kind)
        text = self.text
        found: PrimEvidence = {}
        for profile in _RENDERERS:
            phrases = [
                *_scope_phrases(profile, text),
                *_property_phrases(profile, text, names),
                *_schema_phrases(profile, text, applied),
                *_product_type_phrases(profile, text, product_type),
                *_camera_phrases(profile, text, cameras),
            ]
            if phrases:
                found[profile.name] = phrases
        return found


def _scope_phrases(profile: Profile, path: str) -> list[str]:
    if any(path.startswith(scope) or path + "/" == scope for scope in profile.scopes):
        return [f"the prim <{path}> in {profile.scopes[0].rstrip('/')}"]
    return []


def _property_phrases(profile: Profile, path: str, names: Sequence[str]) -> list[str]:
    if not profile.namespaces:
        return []
    return [
        f"the property <{path}.{name}>" for name in names if name.startswith(profile.namespaces)
    ]


def _schema_phrases(profile: Profile, path: str, applied: Sequence[str]) -> list[str]:
    return [
        f"the API schema {schema} on <{path}>"
        for schema in applied
        if any(fnmatchcase(schema, pattern) for pattern in profile.api_schemas)
    ]


def _product_type_phrases(profile: Profile, path: str, token: str | None) -> list[str]:
    if token and profile.product_types and profile.product_type(token):
        return [f"productType {token!r} of <{path}>"]
    return []


def _camera_phrases(profile: Profile, path: str, cameras: Sequence[Camera]) -> list[str]:
    phrases = []
    for target, camera, type_name in cameras:
        where = f"the camera target <{target}> of <{path}>"
        if profile.runtime_camera(str(target)):
            phrases.append(f"{where}, a camera the renderer's application creates")
        elif camera is not None and profile.camera_type(type_name):
            phrases.append(f"{where}, {describe_prim_type(camera)}")
    return phrases


#: What a render prim holds that can point at a renderer: its authored
#: property names, applied API schemas, productType (a product's; None for
#: others) and camera targets (a settings' or product's).
_Reads = tuple[Sequence[str], Sequence[str], str | None, Sequence[Camera]]


class _Scan:
    """The evidence of one lint's render prims, each read once however many
    scopes share it (vars, cameras), and the root layer's. The prims are read
    through their PrimValues, which the rules read after: one listing of a
    prim's names and one resolution of a relationship serve both."""

    def __init__(self, stage: Usd.Stage | None) -> None:
        self.stage = stage
        self.layer_data = layer_data_evidence(stage)
        # Keyed by the PrimValues (found by the handle's identity): hashing a
        # Usd.Prim is a binding call.
        self._facts: dict[PrimValues, _Facts] = {}
        self._plain: dict[PrimValues, bool] = {}
        self._fallback_plain: dict[tuple[str, tuple[str, ...]], bool] = {}
        # Keyed by a Target's id (a lint resolves each path to one Target,
        # which the entry holds so that its id is not reused): hashing its
        # path is a binding call. A camera's entry says whether it is plain.
        self._cameras: dict[int, tuple[Target, Camera, bool]] = {}
        self._vars: dict[int, tuple[Target, PrimValues | None]] = {}
        self._scopes_present: bool | None = None

    def facts(self, prim: Usd.Prim, kind: str | None = None) -> _Facts:
        """``prim``'s facts; ``kind`` (_SETTINGS, _PRODUCT, _OTHER) when the
        caller knows what the prim is."""
        return self.facts_of(prim_values(prim), kind or _kind(prim))

    def reads(self, values: PrimValues, kind: str) -> _Reads:
        """What the prim holds that can be evidence (all of it read, in this
        order, whether or not some is)."""
        names = values.authored_names()  # listed once per lint, for the rules as well
        applied = values.definition_key()[1]
        product_type = _product_type(values, names) if _PRODUCT_TYPES and kind is _PRODUCT else None
        # A relationship no layer authors has no targets.
        has_camera = kind is not _OTHER and "camera" in names
        return names, applied, product_type, self.cameras(values) if has_camera else ()

    def plain(self, values: PrimValues, kind: str) -> bool:
        """True when no renderer can find evidence on the prim (the common
        case), decided with one test per kind of evidence for all renderers
        together. What :meth:`reads` reads, in its order, each tested as soon
        as it is read: a prim that holds evidence is read again in full
        (_Facts._found)."""
        found = self._plain.get(values)
        if found is not None:
            return found
        found = self._plain[values] = False
        names = values.authored_names()
        key = values.definition_key()
        if key[1]:  # an applied API schema
            return False
        if _PRODUCT_TYPES and kind is _PRODUCT and not self._plain_product_type(values, names, key):
            return False
        if kind is not _OTHER and "camera" in names:
            cameras = self._cameras
            for target in values.targets("camera"):
                entry = cameras.get(id(target))
                if entry is None or entry[0] is not target:
                    entry = self._camera(target)
                if not entry[2]:
                    return False
        # Every namespace ends with ":", which few render prims' names hold:
        # one test of them all together says so first.
        if ":" in "".join(names) and any(map(str.startswith, names, repeat(_NAMESPACES))):
            return False
        present = self._scopes_present
        if present is None:
            present = self.scopes_present()
        if present:
            text = str(values.prim.GetPath())
            if text.startswith(_SCOPES) or any(text + "/" == s for s in _SCOPES):
                return False
        found = self._plain[values] = True
        return found

    def _plain_product_type(
        self, values: PrimValues, names: Sequence[str], key: tuple[str, tuple[str, ...]]
    ) -> bool:
        """Whether a product's productType is no renderer's; for one that no
        layer authors, one answer per definition (``key``: products share the
        schema's fallback)."""
        if "productType" in names:
            token = _product_type(values, names)
            return not (token and _some_product_type(token))
        found = self._fallback_plain.get(key)
        if found is None:
            token = _product_type(values, names)
            found = self._fallback_plain[key] = not (token and _some_product_type(token))
        return found

    def scopes_present(self) -> bool:
        """Whether a prim may lie in a renderer's scope: the prim each scope
        lies under exists (a prim's ancestors always do), asked once per lint
        in place of spelling every render prim's path."""
        found = self._scopes_present
        if found is None:
            stage = self.stage
            found = stage is None or any(stage.GetPrimAtPath(root) for root in _SCOPE_ROOTS)
            self._scopes_present = found
        return found

    def cameras(self, values: PrimValues) -> list[Camera]:
        """A settings or product prim's camera targets and the typed prims there."""
        found = []
        cameras = self._cameras
        for target in values.targets("camera"):
            entry = cameras.get(id(target))
            if entry is None or entry[0] is not target:
                entry = self._camera(target)
            found.append(entry[1])
        return found

    def _camera(self, target: Target) -> tuple[Target, Camera, bool]:
        """A camera target's entry: the target, its Camera, and whether it is
        no renderer's evidence (each target looked at once: settings and
        products share their cameras)."""
        camera = _camera(target)
        _, _, type_name = camera
        plain = not (
            _some_runtime_camera(target.path) or (type_name and _some_camera_type(type_name))
        )
        entry = self._cameras[id(target)] = (target, camera, plain)
        return entry

    def var_values(self, product: PrimValues) -> list[PrimValues]:
        """The usable RenderVars a product's ``orderedVars`` targets, in order."""
        found = []
        known = self._vars
        # A relationship no layer authors has no targets (PrimValues.targets).
        for target in product.targets("orderedVars"):
            # Products share their vars: each target is looked at once.
            entry = known.get(id(target))
            if entry is None or entry[0] is not target:
                entry = known[id(target)] = (target, _usable_var(target))
            if entry[1] is not None:
                found.append(entry[1])
        return found

    def plain_vars(self, product: PrimValues) -> bool:
        """True when no usable RenderVar a product's ``orderedVars`` targets
        holds evidence (:meth:`var_values` and :meth:`plain` of each, without
        a list: products share their vars, most of them already looked at)."""
        known = self._vars
        plain = self._plain
        for target in product.targets("orderedVars"):
            entry = known.get(id(target))
            if entry is None or entry[0] is not target:
                entry = known[id(target)] = (target, _usable_var(target))
            var = entry[1]
            if var is not None and not (plain.get(var) or self.plain(var, _OTHER)):
                return False
        return True

    def vars_of(self, product: _Facts) -> list[_Facts]:
        """The facts of the usable RenderVars a product's ``orderedVars`` targets."""
        found = product.vars
        if found is None:
            facts = self.facts_of
            found = product.vars = [facts(v, _OTHER) for v in self.var_values(product.values)]
        return found

    def facts_of(self, values: PrimValues, kind: str) -> _Facts:
        found = self._facts.get(values)
        if found is None:
            found = self._facts[values] = _Facts(values, kind, self)
        return found

    def infer(self, members: Iterable[_Facts]) -> ProfileChoice:
        """The ``auto`` choice for the render prims of one scope."""
        found = [f.evidence for f in members if f.evidence]
        if not found and not self.layer_data:
            return _NO_EVIDENCE
        hits: dict[str, list[str]] = {}
        for evidence in [*found, self.layer_data]:
            for name, phrases in evidence.items():
                hits.setdefault(name, []).extend(phrases)
        # Reported in the renderers' order, as each renderer's own evidence is.
        return _choice({p.name: hits[p.name] for p in _RENDERERS if p.name in hits})


def _choice(hits: dict[str, list[str]]) -> ProfileChoice:
    """The choice the evidence per renderer makes: one renderer's picks it."""
    if len(hits) == 1:
        name, evidence = next(iter(hits.items()))
        more = f" and {len(evidence) - 1} more" if len(evidence) > 1 else ""
        return ProfileChoice(PROFILES[name], f"auto: {evidence[0]}{more}")
    if not hits:
        return _NO_EVIDENCE
    counts = ", ".join(f"{name}: {len(e)}" for name, e in hits.items())
    return ProfileChoice(
        GENERIC,
        f"auto: evidence of several renderers ({counts}), so the schema alone; "
        "pin one with profile = NAME or --profile",
    )


def layer_data_evidence(stage: Usd.Stage | None) -> PrimEvidence:
    """The keys of the root layer's customLayerData (nested dictionaries'
    keys joined with ":", ``cameraSettings:boundCamera``) that a renderer's
    application writes, per renderer."""
    data = stage.GetRootLayer().customLayerData if stage is not None else None
    if not data:  # most layers hold none
        return {}
    keys = _layer_data_keys(dict(data))
    found: PrimEvidence = {}
    for profile in _RENDERERS:
        phrases = [
            f"the root layer's customLayerData {key}" for key in keys if profile.layer_datum(key)
        ]
        if phrases:
            found[profile.name] = phrases
    return found


def _layer_data_keys(data: dict) -> list[str]:
    keys: list[str] = []
    pending: list[tuple[str, dict]] = [("", data)]
    while pending:
        prefix, data = pending.pop()
        for key, value in data.items():
            keys.append(prefix + key)
            if isinstance(value, dict):
                pending.append((f"{prefix}{key}:", value))
    return keys


#: One scope: its key (its settings' or lone product's path), its prims (with
#: a var once per product targeting it), the prims whose camera targets belong
#: to it, and its settings (None for a lone product).
_Scope = tuple[Sdf.Path, list[_Facts], list[Usd.Prim], Usd.Prim | None]

#: A RenderSettings of the configurations and its products, in order.
_Group = tuple[Usd.Prim, list[Usd.Prim]]


def _grouped(
    configurations: Sequence[RenderConfiguration],
) -> list[tuple[Usd.Prim, list[Usd.Prim]]]:
    """Each RenderSettings of the configurations with its products, in order
    (products on their own, R2-4, are not here)."""
    groups: list[_Group] = []
    last: Usd.Prim | None = None
    for config in configurations:
        settings = config.settings
        if settings is None:
            continue
        # A settings prim's configurations come one after another.
        if settings is not last:
            last = settings
            groups.append((settings, []))
        if config.product is not None:
            groups[-1][1].append(config.product)
    return groups


def _plain_scopes(groups: list[_Group], lone_products: Sequence[Usd.Prim], scan: _Scan) -> bool:
    """True when no prim of any scope holds evidence (the common case): then
    every scope is judged as the stage is, and none needs building. The prims
    are read in the order :func:`_scopes` reads them."""
    plain = scan.plain
    for settings, _ in groups:
        if not plain(prim_values(settings), _SETTINGS):
            return False
    for _, products in groups:
        if not _plain_products(products, scan):
            return False
    return all(_plain_products((p,), scan) for p in lone_products)


def _plain_products(products: Sequence[Usd.Prim], scan: _Scan) -> bool:
    plain = scan.plain
    found = [prim_values(p) for p in products]
    for values in found:
        if not plain(values, _PRODUCT):
            return False
    return all(scan.plain_vars(values) for values in found)


def _scopes(groups: list[_Group], lone_products: Sequence[Usd.Prim], scan: _Scan) -> list[_Scope]:
    """Every scope: each RenderSettings with its products and their vars, then
    each product no settings targets with its vars (R2-4)."""
    grouped: dict[_Facts, tuple[Usd.Prim, list[Usd.Prim]]] = {}
    for settings, products in groups:
        facts = scan.facts(settings, _SETTINGS)
        # A settings prim listed twice (not one after another) is one scope.
        grouped.setdefault(facts, (settings, []))[1].extend(products)
    scopes = [_scope(facts, *group, scan) for facts, group in grouped.items()]
    for product in lone_products:
        facts = scan.facts(product, _PRODUCT)
        scopes.append((facts.path, [facts, *scan.vars_of(facts)], [product], None))
    return scopes


def _scope(facts: _Facts, settings: Usd.Prim, products: list[Usd.Prim], scan: _Scan) -> _Scope:
    found = [scan.facts(p, _PRODUCT) for p in products]
    members = [facts, *found]
    members.extend(v for f in found for v in scan.vars_of(f))
    return facts.path, members, [settings, *products], settings


def _camera_paths(prims: Iterable[Usd.Prim]) -> list[Sdf.Path]:
    found: list[Sdf.Path] = []
    for prim in prims:
        for path in prim_values(prim).forwarded("camera"):
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
    stage: Usd.Stage | None = None,
) -> Assignment:
    """Decide the profile of every scope. ``setting`` is a profile name or
    ``auto``; ``reason`` says where an explicit one was configured;
    ``render_prims`` judge the stage when it has no scope; ``stage`` is theirs
    (by default the stage of the configurations or prims)."""
    if setting != AUTO:
        return _explicit(setting, reason)
    if stage is None:
        stage = _stage_of(configurations, [*lone_products, *render_prims])
    scan = _Scan(stage)
    groups = _grouped(configurations)
    if groups or lone_products:
        plain = _plain_scopes(groups, lone_products, scan)
    else:  # no scope: the stage is judged by its render prims
        plain = all(scan.plain(prim_values(p), _kind(p)) for p in render_prims)
    if plain:
        # Every scope and the stage judged alike, by the root layer's data alone.
        return Assignment({}, {}, scan.infer(()))  # every field by position: no defaults
    scopes = _scopes(groups, lone_products, scan)
    assignment = Assignment()
    for key, members, _, _ in scopes:
        assignment.scopes[key] = scan.infer(members)
    assignment.stage = _stage_choice(assignment, render_prims, scan)
    stage = assignment.stage
    if any(c is not stage and c != stage for c in assignment.scopes.values()):
        # Scopes judged differently: which scopes each prim belongs to matters.
        _add_members(assignment, scopes, passes)
    return assignment


def _explicit(setting: str, reason: str) -> Assignment:
    # One choice for every scope and the stage: no scope needs knowing.
    return Assignment(stage=ProfileChoice(get_profile(setting), reason))


def _add_members(assignment: Assignment, scopes: list[_Scope], passes: Sequence[Usd.Prim]) -> None:
    """Say which scopes each render prim belongs to: its settings, products and
    vars, their cameras, what the settings connect to, the passes rendering it."""
    for key, members, targeting, settings in scopes:
        assignment._add(key, [f.path for f in members])
        assignment._add(key, _camera_paths(targeting))
        if settings is not None:
            assignment._add(key, _connected(settings))
    for render_pass in passes:
        for path in prim_values(render_pass).forwarded("renderSource"):
            if path in assignment.scopes:
                assignment._add(path, [render_pass])


def _stage_of(
    configurations: Sequence[RenderConfiguration], render_prims: Sequence[Usd.Prim]
) -> Usd.Stage | None:
    for config in configurations:
        return config.owner.GetStage()
    return render_prims[0].GetStage() if render_prims else None


def _stage_choice(
    assignment: Assignment, render_prims: Sequence[Usd.Prim], scan: _Scan
) -> ProfileChoice:
    choices = list(dict.fromkeys(assignment.scopes.values()))
    names = {c.name for c in choices}
    if len(names) == 1:
        return choices[0]
    if not names:
        # No configuration (only vars or passes): the render prims' own evidence.
        return scan.infer([scan.facts(p) for p in render_prims])
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
        if setting != AUTO:  # the stage's configurations need not even be known
            return _explicit(setting, reason)
        configurations = ctx.configurations
        lone_products = ctx.untargeted_products
        # The render prims judge the stage only when it has no scope.
        scopeless = not configurations and not lone_products
        return assign(
            configurations,
            lone_products,
            ctx.prims_of(schemas.RenderPass),
            setting,
            reason,
            [p for prims in ctx.render_prims.values() for p in prims] if scopeless else (),
            ctx.stage,
        )
