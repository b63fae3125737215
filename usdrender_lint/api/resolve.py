"""USD resolution shared by every rule: usable prims, relationship targets,
authored and effective values, and the render configuration.

These are the semantics of ``UsdRenderComputeSpec`` (``pxr/usd/usdRender/spec.cpp``),
which usd-core 26.11 does not wrap for Python, re-implemented once here so that
no rule re-derives them (catalog, "Conventions used by every rule").
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Callable, Iterable, Iterator
from functools import cached_property
from itertools import islice
from typing import TYPE_CHECKING, Any, TypeVar

from pxr import Gf, Sdf, Tf, Usd

from ..model import NAMELESS_PROPERTY, CorruptValue
from ..records import record
from . import schemas
from .cache import _ACTIVE, LintCache, cached

if TYPE_CHECKING:
    from pxr import UsdGeom

DEFAULT_TIME = Usd.TimeCode.Default()
_T = TypeVar("_T")

# USD's methods called unbound, on objects known valid (checked with bool(), or
# a property of a prim so checked): the bound form goes through
# Usd.Object.__getattribute__, whose validity check costs several times the
# call (2 us against 0.3 us for IsActive); on an expired prim the unbound
# call would not raise but crash.
_is_active = Usd.Prim.IsActive
_is_defined = Usd.Prim.IsDefined
_is_abstract = Usd.Prim.IsAbstract
_prim_attribute = Usd.Prim.GetAttribute
_prim_relationship = Usd.Prim.GetRelationship
_prim_is_a = Usd.Prim.IsA
_object_path = Usd.Object.GetPath
# A prim's own questions about a property, where ``bool(handle)`` would pass
# the handle to Usd.Object's method (a base-class conversion, ~1,400 instructions).
_has_attribute = Usd.Prim.HasAttribute
_has_relationship = Usd.Prim.HasRelationship
_property_stack = Usd.Property.GetPropertyStack
_has_authored_value = Usd.Attribute.HasAuthoredValue
_get = Usd.Attribute.Get
_spec_type_name = Sdf.AttributeSpec.typeName.fget


#: USD's versioned C++ namespace ("pxrInternal_v0_26_11__pxrReserved__", and
#: "..._pegtl" for the usda grammar's), which its error texts spell out: noise
#: to a user, and it would change a message (a baseline's key) with every USD
#: release.
USD_NAMESPACE = re.compile(r"\bpxrInternal_v\d+_\d+(?:_\d+)?__pxrReserved__(?:_(?=pegtl::)|::)?")


def usd_text(value: object) -> str:
    """``str(value)`` for a USD object whose text may name a file that is not
    UTF-8 (a composition error): the bindings' strict decoding raises, so
    the bytes are decoded as Python names such a file (``os.fsdecode``)."""
    return usd_string(lambda: str(value))


def usd_string(read: Callable[[], str]) -> str:
    """``read()``, a string USD gives (a layer's identifier), decoded as
    :func:`usd_text` decodes one that names a file that is not UTF-8."""
    try:
        return read()
    except UnicodeDecodeError as exc:
        if not isinstance(exc.object, bytes):
            raise
        return os.fsdecode(exc.object)


# -- prims and targets ---------------------------------------------------------


def is_usable(prim: Usd.Prim) -> bool:
    """Active, defined, not abstract: what ``stage.Traverse()`` visits."""
    return bool(prim) and _is_active(prim) and _is_defined(prim) and not _is_abstract(prim)


def unusable_reason(prim: Usd.Prim) -> str | None:
    """Why a prim that exists is not usable, or None when it is usable."""
    if not prim:
        raise RuntimeError(f"not a valid prim: {prim!r}")
    return _unusable_reason(prim)


def _unusable_reason(prim: Usd.Prim) -> str | None:
    if not _is_active(prim):
        return "is inactive"
    if not _is_defined(prim):
        hiding = hiding_over(prim)
        if hiding is None or hiding == prim.GetPath():
            return "is only an 'over' (never defined)"
        # Its own spec is a def, but an ancestor is only an over: Usd
        # composes it as undefined, so traversal never reaches it.
        return f"is under <{hiding}>, which is only an 'over' (never defined)"
    if _is_abstract(prim):
        return "is abstract (a 'class')"
    return None


def hiding_over(prim: Usd.Prim) -> Sdf.Path | None:
    """The nearest of ``prim`` and its ancestors that has no defining
    specifier (only ``over``s), which makes ``prim`` undefined; None when
    ``prim`` is defined."""
    while prim and not prim.IsPseudoRoot():
        if not prim.HasDefiningSpecifier():
            return prim.GetPath()
        prim = prim.GetParent()
    return None


@record(frozen=True)
class Target:
    """One forwarded relationship target and what it resolves to on the stage.

    ``problem`` is None when the target is a usable prim; otherwise it says why
    it is not (missing, a property, inactive, over-only, abstract), phrased to
    follow the target path in a message.
    """

    path: Sdf.Path
    prim: Usd.Prim | None
    problem: str | None

    @property
    def ok(self) -> bool:
        return self.problem is None

    @property
    def usable_prim(self) -> Usd.Prim | None:
        """``prim`` when the target is usable (``ok``), else None."""
        return self.prim if self.problem is None else None

    @property
    def is_missing(self) -> bool:
        return self.prim is None and not self.path.IsPropertyPath()


def resolve_target(stage: Usd.Stage, path: Sdf.Path) -> Target:
    """What ``path`` is on the stage (once per lint: a dozen products target
    the same few vars and cameras)."""
    return _resolved(stage, (path,))[0]


def _resolve_target(stage: Usd.Stage, path: Sdf.Path) -> Target:
    if path.IsPropertyPath():
        return Target(path, None, "is a property, not a prim")
    prim = stage.GetPrimAtPath(path)
    if not prim:
        return Target(path, None, "does not exist on the composed stage")
    return Target(path, prim, _unusable_reason(prim))  # valid: checked above


def _resolved(stage: Usd.Stage, paths: Iterable[Sdf.Path]) -> tuple[Target, ...]:
    """:func:`resolve_target` of each path, kept once per lint in a dictionary
    of the stage's targets by path (some 70 look-ups a CI-gate shot): a key of
    the path alone, where one of (function, (stage, path)) built two tuples
    and compared them on every hit."""
    cache = _ACTIVE.get()
    if cache is None:
        return tuple(_resolve_target(stage, p) for p in paths)
    by_path = _targets_by_path(cache, stage)
    found = []
    for path in paths:
        target = by_path.get(path)
        if target is None:
            target = by_path[path] = _resolve_target(stage, path)
        found.append(target)
    return tuple(found)


def _targets_by_path(cache: LintCache, stage: Usd.Stage) -> dict[Sdf.Path, Target]:
    """The lint's resolved targets of ``stage`` by path (_resolved, know_usable)."""
    return cache._answers.setdefault((_resolved, (stage,)), {})


def know_usable(stage: Usd.Stage, prims: Iterable[Usd.Prim]) -> None:
    """Resolve each of ``prims``' paths to that prim for the running lint: the
    engine's walk visits only usable prims (``stage.Traverse()``'s), so a
    relationship target naming one needs no ``GetPrimAtPath`` and no usability
    checks, and its handle is the one the rules are given (its values found by
    identity, not by hashing a second handle). Nothing outside a lint."""
    cache = _ACTIVE.get()
    if cache is None:
        return
    by_path = _targets_by_path(cache, stage)
    for prim in prims:
        path = values_in(cache, prim).path
        if path not in by_path:
            by_path[path] = Target(path, prim, None)


def forwarded_targets(rel: Usd.Relationship | None) -> list[Sdf.Path]:
    """Targets with relationship forwarding honoured, as spec.cpp reads them."""
    return _targets(rel, forwarded=True)


def authored_targets(rel: Usd.Relationship | None) -> list[Sdf.Path]:
    """The relationship's own composed targets, without forwarding. Read on
    each call, not cached: each reader reads a relationship once per lint
    (PA008 a collection's includes, PA001 and PR005 only for a fix), and a key
    of the handle cost two hashes of it (get, then set; ~10,000 instructions)."""
    return list(_read_targets(rel, False))


def _targets(rel: Usd.Relationship | None, forwarded: bool) -> list[Sdf.Path]:
    return list(_composed_targets((rel, forwarded)))  # a list of its own for each caller


@cached
def _composed_targets(rel_and_mode: tuple[Usd.Relationship | None, bool]) -> tuple[Sdf.Path, ...]:
    return _read_targets(*rel_and_mode)


def _read_targets(rel: Usd.Relationship | None, forwarded: bool) -> tuple[Sdf.Path, ...]:
    if not rel:
        return ()
    return _read_valid_targets(rel, forwarded)


def _read_valid_targets(rel: Usd.Relationship, forwarded: bool) -> tuple[Sdf.Path, ...]:
    try:
        if forwarded:
            return tuple(Usd.Relationship.GetForwardedTargets(rel))
        return tuple(Usd.Relationship.GetTargets(rel))
    except Tf.ErrorException as exc:
        # An opinion authors the name as an attribute (`string camera = "/Cam"`):
        # Pcp composes no targets from it ("... is not a relationship"), so no
        # consumer sees any. Any other error (a corrupt crate value) is the
        # file's problem and goes to the engine.
        if "is not a relationship" not in str(exc):
            raise
        return ()


def resolve_targets(rel: Usd.Relationship | None) -> list[Target]:
    """The relationship's forwarded targets, resolved (a list of its own for
    each caller)."""
    return list(_resolved_targets(rel))


@cached
def _resolved_targets(rel: Usd.Relationship | None) -> tuple[Target, ...]:
    # Several rules and the profiles resolve the same relationships: once per lint.
    if not rel:
        return ()
    stage = rel.GetStage()
    return _resolved(stage, forwarded_targets(rel))


def describe_prim_type(prim: Usd.Prim) -> str:
    type_name = prim.GetTypeName()
    if not type_name:
        return "a typeless prim"
    article = "an" if type_name[0] in "AEIOUX" else "a"
    return f"{article} {type_name}"


def typed_target_problem(target: Target, schema: type, expected: str) -> str | None:
    """Why a target is not a usable prim of ``schema`` (e.g. ``schemas.RenderPass``,
    ``expected`` = "a RenderPass"), phrased to follow the target path in a
    message; None when it is one."""
    prim = target.usable_prim
    if prim is None:
        return target.problem
    if not prim_values(prim).is_a(schema):
        return f"is {describe_prim_type(prim)}, not {expected}"
    return None


# -- values -----------------------------------------------------------------


#: What a prim definition is built from: schema type name and applied API schemas.
_DefinitionKey = tuple[str, tuple[str, ...]]


@record(frozen=True)
class SchemaAttribute:
    """What a prim definition declares for an attribute name."""

    #: None when the definition has no attribute of that name.
    type_name: Sdf.ValueTypeName | None
    allowed_tokens: tuple[str, ...]
    #: Declared ``uniform``.
    uniform: bool = False
    #: ``type_name.type``, kept with it (reading it is a binding call).
    value_type: Tf.Type | None = None
    #: A spec's default of this type is the value ``Get()`` returns at Default
    #: when that spec is the strongest opinion: not an array (an array edit
    #: composes with weaker opinions), an asset (``Get`` resolves it), a time
    #: code (layer offsets apply) or a path expression (mapped across arcs).
    plain: bool = False


#: Per definition key, then attribute name, kept for the whole process: USD
#: composes a prim definition from its key alone, and builds its schema
#: registry once (later plugin registrations do not change it). A prim's
#: PrimValues holds its definition's dictionary: a question is then one
#: look-up by name, where a (key, name) tuple was built and hashed per question
#: (some 230 a CI-gate shot).
_SCHEMA_ATTRIBUTES: dict[_DefinitionKey, dict[str, SchemaAttribute]] = {}


def _declared_attribute(definition: Usd.PrimDefinition, name: str) -> SchemaAttribute:
    attribute = definition.GetAttributeDefinition(name)
    if not attribute:
        return SchemaAttribute(None, ())
    tokens = tuple(str(t) for t in attribute.GetMetadata("allowedTokens") or ())
    uniform = attribute.GetVariability() == Sdf.VariabilityUniform
    type_name = attribute.GetTypeName()
    plain = not type_name.isArray and str(type_name) not in _COMPOSED_SCALARS
    return SchemaAttribute(type_name, tokens, uniform, type_name.type, plain)


#: Scalar value types whose composed value is not a spec's default as authored.
_COMPOSED_SCALARS = frozenset(("asset", "timecode", "pathExpression", "opaque", "group"))


@cached
def _schema_type(attr: Usd.Attribute) -> Sdf.ValueTypeName | None:
    return prim_values(attr.GetPrim()).schema_attribute(attr.GetName()).type_name


#: One spec of an attribute's property stack and what the checks read of it,
#: each read once: whether it holds a default value and time samples, and its
#: value type.
_Opinion = tuple[Sdf.AttributeSpec, bool, bool, Tf.Type]
#: An attribute's opinions, strongest first, its declared value type,
#: whether every opinion has that type (then none is mismatched: most
#: attributes, and every check stops there), and the strongest opinion's
#: default (None when it has none).
_Stack = tuple[tuple[_Opinion, ...], Tf.Type, bool, Any]


@cached
def _attribute_specs(attr: Usd.Attribute) -> _Stack:
    return _read_attribute_specs(attr)


def _read_attribute_specs(attr: Usd.Attribute, samples: bool = True) -> _Stack:
    """The attribute's property stack without relationship specs (a layer may
    author the name as ``rel dataWindowNDC = </X>``, which has no type or
    value), and its declared type: the composed value type, which USD takes
    from the prim definition for a schema attribute (whatever the specs say),
    else from the strongest spec. A spec of that type is never mismatched, so
    most checks stop there. Read together: every reader of one needs the other.
    ``samples``: as for :func:`_attribute_stack`."""
    type_name = attr.GetTypeName()
    return _attribute_stack(attr, type_name.type, type_name, samples)


def _attribute_stack(
    attr: Usd.Attribute, declared: Tf.Type, declared_name: Sdf.ValueTypeName, samples: bool = True
) -> _Stack:
    """``declared_name``: the value type name whose type is ``declared``.
    ``samples``: False when no layer can hold time samples (LintCache.without_varying)."""
    return _stack_of(_property_stack(attr, DEFAULT_TIME), declared, declared_name, samples)


def _stack_of(
    specs: Iterable[Sdf.PropertySpec],
    declared: Tf.Type,
    declared_name: Sdf.ValueTypeName,
    samples: bool,
) -> _Stack:
    """The :data:`_Stack` of an attribute whose property stack is ``specs``."""
    # Every check reads the same few facts of each spec: once, here.
    opinions: list[_Opinion] = []
    well_typed = True
    first_default = None
    for spec in specs:
        if isinstance(spec, Sdf.AttributeSpec):
            type_name = _spec_type_name(spec)
            # Most specs have the declared type name: one comparison, where
            # reading the type and comparing it are two binding calls.
            if type_name == declared_name:
                value_type = declared
            else:
                value_type = type_name.type
                if well_typed and value_type != declared:
                    well_typed = False
            has_samples = samples and _has_time_samples(spec)
            if opinions:
                has_default = spec.HasDefaultValue()
            else:
                # The strongest default is what most checks read next: read
                # in place of asking whether there is one (None: there is not).
                first_default = spec.default
                has_default = first_default is not None
            opinions.append((spec, has_default, has_samples, value_type))
    return tuple(opinions), declared, well_typed, first_default


@cached
def mismatched_spec(attr: Usd.Attribute) -> Sdf.AttributeSpec | None:
    """The strongest value-holding spec whose type differs from the schema's.

    Python ``Get()`` returns such a value (e.g. a ``Gf.Vec2f`` for a ``float``)
    although typed C++ reads cannot (catalog, Surprises 5). Roles are ignored:
    ``color3f`` and ``float3`` store the same value type.
    """
    return _mismatched_in(_attribute_specs(attr), lambda: _schema_type(attr))


def _mismatched_in(
    stack: _Stack, schema_type: Callable[[], Sdf.ValueTypeName | None]
) -> Sdf.AttributeSpec | None:
    opinions, declared, well_typed, _ = stack
    if well_typed:
        return None
    for spec, has_default, has_samples, value_type in opinions:
        if has_default or has_samples:
            if value_type == declared:
                return None
            declared_name = schema_type()  # read only when the types differ
            return spec if declared_name is not None and value_type != declared_name.type else None
    return None


def _has_time_samples(spec: Sdf.AttributeSpec) -> bool:
    # HasInfo is the cheaper call and false for most specs (`.timeSamples = {}` has
    # the field but no samples, so it only filters).
    return spec.HasInfo("timeSamples") and spec.layer.GetNumTimeSamplesForPath(spec.path) > 0


def mismatched_specs(attr: Usd.Attribute) -> list[Sdf.AttributeSpec]:
    """Every spec of the attribute, strongest first, whose type differs from the
    schema's, value-holding or not (what ``usdValidation:AttributeTypeMismatch``
    reports). Roles are ignored, as in :func:`mismatched_spec`."""
    return _specs_of_other_types(_attribute_specs(attr), lambda: _schema_type(attr))


def _specs_of_other_types(
    stack: _Stack, schema_type: Callable[[], Sdf.ValueTypeName | None]
) -> list[Sdf.AttributeSpec]:
    opinions, _, well_typed, _ = stack
    if well_typed:
        return []
    declared_name = schema_type()  # read only when some spec differs
    if declared_name is None:
        return []
    schema_value_type = declared_name.type
    return [o[0] for o in opinions if o[3] != schema_value_type]


def allowed_tokens(prim: Usd.Prim, name: str) -> tuple[str, ...]:
    """The schema's ``allowedTokens`` for an attribute, read from the prim
    definition at run time; empty when the schema declares none."""
    return prim_values(prim).schema_attribute(name).allowed_tokens


@cached
def has_authored_value(attr: Usd.Attribute | None) -> bool:
    """Authored and well-typed: type-mismatched opinions count as unauthored
    (catalog, Conventions: one mistake gives one finding, SE016)."""
    if not attr or not _has_authored_value(attr):
        return False
    return _holds_well_typed_value(_attribute_specs(attr), lambda: _schema_type(attr))


def _holds_well_typed_value(
    stack: _Stack, schema_type: Callable[[], Sdf.ValueTypeName | None]
) -> bool:
    """Whether an attribute with an authored value (``stack``, its opinions,
    and ``schema_type``, what its schema declares) holds a well-typed one."""
    # The first value-holding spec of the property stack must have the schema's
    # type (as _mismatched_in reads it), and neither the first default nor the
    # first time samples may be a path: usda accepts ``<...>`` as the value of an
    # attribute of any type (``uniform token sourceType = </X>``, also in time
    # samples), an Sdf.Path no typed read returns.
    opinions, declared, well_typed, first_default = stack
    if well_typed and len(opinions) == 1 and not opinions[0][2]:
        # One opinion of the declared type without time samples (every attribute
        # of a one-layer shot): only its default can hold a path.
        return not isinstance(first_default, Sdf.Path)
    count = default_at = samples_at = len(opinions)
    for index, (_, has_default, has_samples, _) in enumerate(opinions):
        if has_default and default_at == count:
            default_at = index
        if has_samples and samples_at == count:
            samples_at = index
    first = min(default_at, samples_at)
    if first == count:
        return True  # no spec holds a value
    single = ((opinions[first],), declared, False, None)
    if not well_typed and _mismatched_in(single, schema_type) is not None:
        return False
    if default_at < count:
        default = first_default if default_at == 0 else opinions[default_at][0].default
        if isinstance(default, Sdf.Path):
            return False
    return samples_at == count or not _path_in_samples(opinions[samples_at][0])


def _path_in_samples(spec: Sdf.AttributeSpec) -> bool:
    return any(isinstance(v, Sdf.Path) for v in spec.GetInfo("timeSamples").values())


def fallback_value(prim: Usd.Prim, name: str) -> Any:
    return prim_values(prim).fallback(name)


def authored_value(attr: Usd.Attribute | None, time: Usd.TimeCode = DEFAULT_TIME) -> Any:
    """The attribute's value when it is authored and well-typed, else None.
    At Default it is read once per lint: every rule that reads the attribute
    shares it (a crate unpacks a large array anew on each read). Treat it as
    read-only."""
    if time is DEFAULT_TIME or time.IsDefault():
        return _authored_default(attr)
    if attr is None or not has_authored_value(attr):
        return None
    return attr.Get(time)


@cached
def _authored_default(attr: Usd.Attribute | None) -> Any:
    if attr is None or not has_authored_value(attr):
        return None
    return attr.Get(DEFAULT_TIME)


def composed_value(prim: Usd.Prim, name: str, time: Usd.TimeCode = DEFAULT_TIME) -> Any:
    """The value a consumer reads (at Default unless ``time`` says otherwise):
    authored (well-typed) or fallback. At Default it is read once per lint
    (:class:`PrimValues`); treat it as read-only."""
    if time is DEFAULT_TIME or time.IsDefault():
        return prim_values(prim).composed(name)
    attr = prim.GetAttribute(name)
    if has_authored_value(attr):
        return attr.Get(time)
    return fallback_value(prim, name)


def authored_property_names(prim: Usd.Prim) -> list[str]:
    """``prim.GetAuthoredPropertyNames()``, raising CorruptValue (ST001) for a
    property named "": the name list does not check it, while every property
    object USD makes of it fails a verification (UsdStage::_GetDefiningSpecType).
    Listed once per lint (:meth:`PrimValues.authored_names`)."""
    return list(prim_values(prim).authored_names())


class PrimValues:
    """What the rules read of one prim, by property name, each read once per
    lint and shared by every rule and helper: its attributes' authored and
    composed values at Default, their type mismatches, its relationships'
    targets. Get it with :func:`prim_values`; treat its values as read-only.

    Its memo is keyed by names, not by USD objects: hashing a ``Usd.Attribute``
    (a fresh handle at every ``GetAttribute``) and comparing it on a hit cost
    two binding calls, more than most answers save (a CI-gate shot made 2,000
    such calls). The answers are those of :func:`has_authored_value`,
    :func:`authored_value`, :func:`composed_value`, :func:`mismatched_spec`,
    :func:`forwarded_targets` and :func:`resolve_targets` (the same code).
    """

    __slots__ = (
        "prim",
        "_attrs",
        "_rels",
        "_specs",
        "_has",
        "_authored",
        "_composed",
        "_varying",
        "_forwarded",
        "_targets",
        "_definition",
        "_key",
        "_declared",
        "_names",
        "_names_decide",
        "_without_varying",
        "_listed",
        "_own_properties",
        "_kinds",
        "_memo",
        "_path",
    )

    def __init__(
        self, prim: Usd.Prim, without_clips: bool = False, without_varying: bool = False
    ) -> None:
        if not prim:  # its methods call USD unbound: on a valid prim only
            raise RuntimeError(f"not a valid prim: {prim!r}")
        self.prim = prim
        self._attrs: dict[str, Usd.Attribute] = {}
        self._rels: dict[str, Usd.Relationship] = {}
        self._specs: dict[str, _Stack] = {}
        self._has: dict[str, bool] = {}
        self._authored: dict[str, Any] = {}
        self._composed: dict[str, Any] = {}
        self._varying: dict[str, bool] = {}
        self._forwarded: dict[str, tuple[Sdf.Path, ...]] = {}
        self._targets: dict[str, tuple[Target, ...]] = {}
        self._definition: Usd.PrimDefinition | None = None
        self._key: _DefinitionKey | None = None
        self._declared: dict[str, SchemaAttribute] | None = None
        self._names: tuple[str, ...] | None = None
        #: Whether an attribute that the authored property names do not list
        #: holds no authored value (a stage without value clips:
        #: LintCache.without_clips); ``_listed`` is those names, once asked.
        self._names_decide = without_clips
        #: No spec of the stage holds time samples or a spline (LintCache.without_varying).
        self._without_varying = without_varying
        self._listed: frozenset[str] | None = None
        #: _read_own_properties's answer, once asked.
        self._own_properties: Any = None
        #: IsA answers by the schema's id (hashing a Tf.Type is a binding call).
        self._kinds: dict[int, tuple[Any, bool]] = {}
        #: ``Context.cached`` answers of this prim, by function.
        self._memo: dict[Callable[..., Any], Any] = {}
        self._path: Sdf.Path | None = None

    @property
    def path(self) -> Sdf.Path:
        """``prim.GetPath()``, asked once: the method is Usd.Object's, so every
        call converts the prim handle to it (~2 us, twice the call itself)."""
        path = self._path
        if path is None:
            path = self._path = _object_path(self.prim)
        return path

    def attribute(self, name: str) -> Usd.Attribute:
        """``prim.GetAttribute(name)``, one handle per name."""
        attr = self._attrs.get(name)
        if attr is None:
            attr = self._attrs[name] = _prim_attribute(self.prim, name)
        return attr

    def is_a(self, schema: Tf.Type | type) -> bool:
        """``prim.IsA(schema)``, asked once per schema: rules test the same
        relationship targets (vars, cameras) for every product."""
        entry = self._kinds.get(id(schema))
        if entry is None or entry[0] is not schema:
            # The entry holds the schema, so that its id is not reused.
            entry = self._kinds[id(schema)] = (schema, self._read_is_a(schema))
        return entry[1]

    def _read_is_a(self, schema: Tf.Type | type) -> bool:
        if _RENDER_SCHEMAS.get(id(schema)) is not schema:
            return _prim_is_a(self.prim, schema)
        # UsdPrim::IsA asks only the prim's schema type (GetPrimTypeInfo().
        # GetSchemaType(), pxr/usd/usd/prim.cpp), which its schema type name
        # names: a render schema's answer is kept per type name for the process.
        key = (self.definition_key()[0], id(schema))
        found = _SCHEMA_IS_A.get(key)
        if found is None:
            found = _SCHEMA_IS_A[key] = _prim_is_a(self.prim, schema)
        return found

    def relationship(self, name: str) -> Usd.Relationship:
        """``prim.GetRelationship(name)``, one handle per name."""
        rel = self._rels.get(name)
        if rel is None:
            rel = self._rels[name] = _prim_relationship(self.prim, name)
        return rel

    def _attribute_specs(self, name: str, schema: SchemaAttribute | None = None) -> _Stack:
        """``schema``: :meth:`schema_attribute` of ``name``, when the caller has it."""
        found = self._specs.get(name)
        if found is None:
            # A schema attribute's composed type is the definition's (whatever
            # the specs say): known without asking the attribute.
            if schema is None:
                schema = self.schema_attribute(name)
            declared = schema.value_type
            if declared is None:
                found = _read_attribute_specs(self.attribute(name), not self._without_varying)
            elif name not in (self._listed or self._listed_names()):
                # The Default property stack holds the prim's own specs only
                # (never value clips), and no layer has one of this name.
                found = ((), declared, True, None)
            else:
                own = self._own_properties
                if own is None:
                    own = self._read_own_properties()
                if own is not False:
                    # The prim's only spec holds the only spec of this name.
                    spec = own.get(name)
                    found = _stack_of(
                        () if spec is None else (spec,),
                        declared,
                        schema.type_name,
                        not self._without_varying,
                    )
                else:
                    found = _attribute_stack(
                        self.attribute(name), declared, schema.type_name, not self._without_varying
                    )
            self._specs[name] = found
        return found

    def _read_own_properties(self) -> Any:
        """The property specs of the prim's only spec (``primSpec.properties``),
        or False when more than one spec (or none) contributes to the prim.

        A property spec lies under a prim spec of its layer, and a prim's
        property stack at Default is read from the sites of its prim stack
        (``UsdPrim::GetPrimStack``, ``UsdProperty::GetPropertyStack``; value
        clips only count at a numeric time): with one prim spec, an attribute's
        stack is that spec's property of its name, if any. One call for the
        prim in place of a property stack per attribute (a CI-gate shot's
        render prims each have one spec and some 2.5 attributes read)."""
        specs = Usd.Prim.GetPrimStack(self.prim)
        own = self._own_properties = specs[0].properties if len(specs) == 1 else False
        return own

    def has_value(self, name: str) -> bool:
        """:func:`has_authored_value` of the named attribute."""
        found = self._has.get(name)
        if found is None:
            # may_be_authored inlined: most names asked are authored by no layer.
            listed = self._listed
            if self._names_decide and name not in (
                listed if listed is not None else self._listed_names()
            ):
                found = False  # no handle and no HasAuthoredValue needed
            else:
                found = self._holds_value(name)
            self._has[name] = found
        return found

    def _holds_value(self, name: str) -> bool:
        # The declaration is read once here and handed on (each method asking
        # it again was a call per question).
        declared = self._declared
        schema = declared.get(name) if declared is not None else None
        if schema is None:
            schema = self.schema_attribute(name)
        # A name the prim definition declares as an attribute is one whatever
        # the layers author (UsdStage::_GetDefiningSpecType asks the definition
        # first): no HasAttribute needed.
        if schema.value_type is None and not _has_attribute(self.prim, name):
            return False
        stack = self._specs.get(name) or self._attribute_specs(name, schema)
        default = None
        if self._names_decide:
            # Without value clips the strongest spec that holds a value decides
            # (UsdResolveInfo reads the stack strongest first): a default that
            # is no block is an authored value, known without HasAuthoredValue.
            default = stack[3]
            if isinstance(default, _BLOCKS):
                default = None
        if default is None and not _has_authored_value(self.attribute(name)):
            return False
        if not _holds_well_typed_value(stack, lambda: schema.type_name):
            return False
        if default is not None and schema.plain:
            # At Default, Get() returns the strongest default (time samples and
            # splines do not count there): the value is already read.
            self._authored[name] = default
        return True

    def authored(self, name: str) -> Any:
        """:func:`authored_value` of the named attribute at Default."""
        value = self._authored.get(name, _UNREAD)
        if value is _UNREAD:
            has = self._has.get(name)
            if not (has if has is not None else self.has_value(name)):
                value = None
            else:
                # has_value may have read it (the strongest spec's default).
                value = self._authored.get(name, _UNREAD)
                if value is _UNREAD:
                    value = _get(self.attribute(name))
            self._authored[name] = value
        return value

    def fallback(self, name: str) -> Any:
        """The schema's fallback for the named attribute (None when it has none),
        read once per lint and prim definition (a dozen products share theirs;
        ``composed`` keeps what it read of it)."""
        return _definition_fallback(self, name)

    def composed(self, name: str) -> Any:
        """:func:`composed_value` of the named attribute at Default."""
        value = self._composed.get(name, _UNREAD)
        if value is _UNREAD:
            has = self._has.get(name)
            if has if has is not None else self.has_value(name):
                value = self._authored.get(name, _UNREAD)
                if value is _UNREAD:
                    value = self.authored(name)
            else:
                value = self.fallback(name)
            self._composed[name] = value
        return value

    def mismatched_specs(self, name: str) -> list[Sdf.AttributeSpec]:
        """:func:`mismatched_specs` of the named attribute."""
        stack = self._specs.get(name) or self._attribute_specs(name)
        if stack[2]:  # every opinion has the declared type (most attributes): none differs
            return []
        return _specs_of_other_types(stack, lambda: self.schema_attribute(name).type_name)

    def authored_names(self) -> tuple[str, ...]:
        """The names of the prim's authored properties, in USD's order
        (:func:`authored_property_names`)."""
        names = self._authored_names()
        if "" in names:
            raise CorruptValue(NAMELESS_PROPERTY)
        return names

    def may_vary(self, name: str) -> bool:
        """False when the named attribute provably has neither time samples
        nor a spline: the stage has no value clips and no opinion holds
        either (then ``GetNumTimeSamples()`` is 0 and its value's source is
        no varying one, known without asking the attribute)."""
        found = self._varying.get(name)
        if found is None:
            found = not self._names_decide or (
                not self._without_varying
                and any(
                    has_samples or spec.HasInfo("spline")
                    for spec, _, has_samples, _ in self._attribute_specs(name)[0]
                )
            )
            self._varying[name] = found
        return found

    def may_be_authored(self, name: str) -> bool:
        """False when the named property provably has no opinion at all: no
        layer's spec names it and the stage has no value clips (which give
        values to attributes no spec names)."""
        if not self._names_decide:
            return True
        listed = self._listed  # _listed_names inlined: some 200 calls a shot
        return name in (listed if listed is not None else self._listed_names())

    def _authored_names(self) -> tuple[str, ...]:
        # Listed once, unchecked: has_value only looks names up in it.
        names = self._names
        if names is None:
            names = self._names = tuple(Usd.Prim.GetAuthoredPropertyNames(self.prim))
        return names

    def _listed_names(self) -> frozenset[str]:
        listed = self._listed
        if listed is None:
            listed = self._listed = frozenset(self._authored_names())
        return listed

    def mismatched(self, name: str) -> Sdf.AttributeSpec | None:
        """:func:`mismatched_spec` of the named attribute."""
        stack = self._specs.get(name) or self._attribute_specs(name)
        if stack[2]:  # every opinion has the declared type (most attributes): none differs
            return None
        return _mismatched_in(stack, lambda: self.schema_attribute(name).type_name)

    def forwarded(self, name: str) -> tuple[Sdf.Path, ...]:
        """:func:`forwarded_targets` of the named relationship."""
        paths = self._forwarded.get(name)
        if paths is None:
            if name not in (self._listed or self._listed_names()):
                paths = ()  # no layer authors it (value clips hold no targets)
            else:
                # Read here, not through the handle-keyed cache of
                # forwarded_targets: hashing a relationship handle (and
                # comparing it on a hit) are binding calls, and every reader of
                # a render prim's targets (rules, profiles) comes through here.
                has = _has_relationship(self.prim, name)
                paths = _read_valid_targets(self.relationship(name), True) if has else ()
            self._forwarded[name] = paths
        return paths

    def targets(self, name: str) -> tuple[Target, ...]:
        """:func:`resolve_targets` of the named relationship."""
        found = self._targets.get(name)
        if found is None:
            if name not in (self._listed or self._listed_names()):
                found = ()  # no layer authors it (value clips hold no targets)
            else:
                found = _resolved(Usd.Prim.GetStage(self.prim), self.forwarded(name))
            self._targets[name] = found
        return found

    @property
    def definition(self) -> Usd.PrimDefinition:
        definition = self._definition
        if definition is None:
            definition = self._definition = Usd.Prim.GetPrimDefinition(self.prim)
        return definition

    def definition_key(self) -> tuple[str, tuple[str, ...]]:
        """What the prim's definition is built from: its schema type name and
        the API schemas applied to it (``Usd.PrimTypeInfo``: the authored
        ones, not those the type's definition includes)."""
        key = self._key
        if key is None:
            info = Usd.Prim.GetPrimTypeInfo(self.prim)
            key = self._key = (info.GetSchemaTypeName(), tuple(info.GetAppliedAPISchemas()))
        return key

    def schema_attribute(self, name: str) -> SchemaAttribute:
        """What the prim's definition declares for the attribute ``name``."""
        declared = self._declared
        if declared is None:
            declared = self._declared = _SCHEMA_ATTRIBUTES.setdefault(self.definition_key(), {})
        found = declared.get(name)
        if found is None:
            found = declared[name] = _declared_attribute(self.definition, name)
        return found


#: The schemas rules test prims against (module constants, so their ids stay
#: theirs), by id: IsA against one of them is answered once per process and
#: schema type name (PrimValues.is_a; a call into USD costs some 5,000
#: instructions, a gate shot made 37).
_RENDER_SCHEMAS: dict[int, Tf.Type] = {
    id(s): s
    for s in (
        schemas.RenderSettingsBase,
        schemas.RenderSettings,
        schemas.RenderProduct,
        schemas.RenderVar,
        schemas.RenderPass,
        schemas.Camera,
    )
}
_SCHEMA_IS_A: dict[tuple[str, int], bool] = {}
_UNREAD: Any = object()
#: ``_ACTIVE.get``, bound once (prim_values: some 800 calls a shot).
_active = _ACTIVE.get
#: Defaults that hold no value: a value block, and an animation block (which
#: leaves the default to weaker opinions and blocks their samples).
_BLOCKS = (Sdf.ValueBlock, Sdf.AnimationBlock)


def _definition_fallback(values: PrimValues, name: str) -> Any:
    """The fallback of ``name`` in the definition of ``values``' prim, read
    once per lint and definition (a dozen products share theirs)."""
    cache = _ACTIVE.get()
    if cache is None:
        return values.definition.GetAttributeFallbackValue(name)
    key = (_definition_fallback, (values.definition_key(), name))
    value = cache._answers.get(key, _UNREAD)
    if value is _UNREAD:
        value = cache._answers[key] = values.definition.GetAttributeFallbackValue(name)
    return value


def prim_values(prim: Usd.Prim) -> PrimValues:
    """The prim's :class:`PrimValues` of the running lint (a new one outside a lint)."""
    cache = _active()
    if cache is not None:
        # The engine hands every rule the same prim handles: found by identity
        # (an id of a handle the lint holds is no other live object's).
        values = cache.by_identity.get(id(prim))
        if values is not None:
            return values
    return values_in(cache, prim)


def values_in(cache: LintCache | None, prim: Usd.Prim) -> PrimValues:
    """The prim's :class:`PrimValues` in a lint's cache (a new one without a cache)."""
    if cache is None:
        return PrimValues(prim)
    values = cache.by_identity.get(id(prim))
    if values is not None:
        return values
    # Another handle of a prim seen before (a relationship target) shares its
    # values, held in a list so that a new prim's handle is hashed once, not
    # twice (get, then set): hashing a prim handle is a call into USD.
    held = cache._answers.setdefault((PrimValues, (prim,)), [])
    if not held:
        held.append(PrimValues(prim, cache.without_clips, cache.without_varying))
    values = held[0]
    # The list holds the handle until the lint ends, so that its id is not reused:
    # then a lookup by id needs no check that it found this handle.
    held.append(prim)
    cache.by_identity[id(prim)] = values
    return values


def forget_prim_answers(cache: LintCache) -> None:
    """Drop what ``Context.cached`` kept on the lint's prims, as the lint ends. An
    answer that holds its prim's values (or anything that does) makes a reference
    cycle, which only the cyclic garbage collector would free, in collections that
    walk every young object (on a CI gate, one cycle per render prim cost 0.5 ms a shot)."""
    for values in cache.by_identity.values():
        values._memo.clear()


def items(value: Any) -> list[Any]:
    """The elements of a Gf vector or Vt array (or any sized sequence), in order.

    Iterating a Gf vector or Vt array runs until its C++ ``__getitem__`` raises
    IndexError, which costs ~10 us per loop (``min``, ``list``, unpacking and
    ``dict.fromkeys`` all iterate); stopping at its length costs ~1 us, and a
    Gf vector's slice (a new list, one binding call) ~0.5 us.
    """
    if value.__class__ in _GF_VECTORS:
        return value[:]
    return list(islice(value, len(value)))


#: The Gf vector types, whose binding slices to a list of the components (a Vt
#: array slices to another array, a Gf matrix not at all).
_GF_VECTORS = frozenset(
    getattr(Gf, f"Vec{size}{kind}") for size in (2, 3, 4) for kind in ("d", "f", "h", "i")
)


def is_finite(value: Any) -> bool:
    """True when every component of a scalar or Gf vector is finite."""
    if isinstance(value, (int, float)):
        return math.isfinite(value)
    if value.__class__ in _GF_VECTORS:  # numbers only: no type test per component
        return all(map(math.isfinite, value[:]))
    try:
        components = items(value)
    except TypeError:
        try:
            components = list(value)
        except TypeError:
            components = [value]
    return all(isinstance(c, (int, float)) and math.isfinite(c) for c in components)


def time_samples(attr: Usd.Attribute, cap: int) -> list[float]:
    """The first ``cap`` authored time samples of an attribute."""
    if not attr:
        return []
    return list(attr.GetTimeSamples())[:cap]


def joint_evaluation_times(attrs: Iterable[Usd.Attribute], cap: int) -> Iterator[Usd.TimeCode]:
    """Default, then the sorted union of the attributes' authored time samples
    (capped in total): where a check of a varying render-prim value that
    Revision 2 leaves alone (PR002's productName) is evaluated. Camera inputs
    are read at :func:`rendered_times` instead."""
    yield DEFAULT_TIME
    union = sorted({t for attr in attrs for t in time_samples(attr, cap)})
    for t in union[:cap]:
        yield Usd.TimeCode(t)


def rendered_times(attrs: Iterable[Usd.Attribute], cap: int) -> list[Usd.TimeCode]:
    """The times at which a renderer reads these varying attributes (catalog
    Revision 2, R2-1 "Rendered times").

    Hydra-based renderers read a varying attribute at the frame being rendered,
    and at a numeric time an attribute's time samples beat its default value.
    So:

    - none of the attributes has a (well-typed) time sample: ``[Default]``;
    - the stage authors both ``startTimeCode`` and ``endTimeCode`` (root or
      session layer, as ``Usd.Stage.HasAuthoredTimeCodeRange`` reads them; a
      range in a sublayer does not count): the attributes' sample times inside
      ``[start, end]`` plus both ends, whose values are held (or interpolated)
      from the nearest samples, so samples that all lie outside the range
      still give the values rendered at its ends;
    - otherwise: every sample time of the attributes.

    Default is then not a rendered time. Sample times are stage times (layer
    offsets and value clips applied, as ``Usd.Attribute.GetTimeSamples``
    reports them); the result is sorted and holds at most ``cap`` times. The
    stage range is read from the attributes' stage. A type-mismatched opinion
    counts as unauthored (SE016), so its samples are not rendered times.
    """
    return authored_rendered_times([a for a in attrs if a and has_authored_value(a)], cap)


def authored_rendered_times(attrs: Iterable[Usd.Attribute], cap: int) -> list[Usd.TimeCode]:
    """:func:`rendered_times` of attributes already known to hold well-typed
    authored values (:meth:`PrimValues.has_value`)."""
    sampled = [a for a in attrs if a.GetNumTimeSamples() != 0]
    if not sampled:
        return [DEFAULT_TIME]
    stage = sampled[0].GetStage()
    interval: Gf.Interval | None = None
    if stage.HasAuthoredTimeCodeRange():
        interval = Gf.Interval(stage.GetStartTimeCode(), stage.GetEndTimeCode())
    times: set[float] = set()
    for attr in sampled:
        if interval is None:
            times.update(time_samples(attr, cap))
        else:
            times.update(islice(attr.GetTimeSamplesInInterval(interval), cap))
    if interval is not None:
        times.update((interval.min, interval.max))
    return [Usd.TimeCode(t) for t in sorted(times)[:cap]]


def format_time(time: Usd.TimeCode) -> str:
    return "the default time" if time.IsDefault() else f"time {time.GetValue():g}"


# -- render configuration --------------------------------------------------------

SETTINGS_BASE_ATTRIBUTES = (
    "aspectRatioConformPolicy",
    "dataWindowNDC",
    "disableDepthOfField",
    "disableMotionBlur",
    "instantaneousShutter",
    "pixelAspectRatio",
    "resolution",
)


@record(frozen=True)
class EffectiveValue:
    """A RenderSettingsBase value in a configuration and where it comes from."""

    value: Any
    #: The attribute that supplies the value (the product's when it overrides).
    attr: Usd.Attribute
    authored: bool


@record(frozen=True)
class RenderConfiguration:
    """The unit a renderer renders: a RenderSettings paired with one usable
    RenderProduct of its ``products`` (or alone when it has none), as
    ``UsdRenderComputeSpec`` builds it, or a product rendered on its own.

    A product rendered on its own (``settings`` is None) is a usable product
    that no usable RenderSettings targets and whose own ``camera`` has a
    forwarded target: renderers that address products by prim path render it
    with its own values and the schema fallbacks (catalog R2-4).
    """

    settings: Usd.Prim | None
    product: Usd.Prim | None = None

    def __post_init__(self) -> None:
        if self.settings is None and self.product is None:
            raise ValueError("a render configuration needs a settings or a product prim")

    @property
    def owner(self) -> Usd.Prim:
        """The prim that stands for the whole configuration (where its findings
        and settings-level fixes go): the settings, or the product rendered on
        its own."""
        owner = self.settings if self.settings is not None else self.product
        assert owner is not None  # __post_init__
        return owner

    @property
    def rendered_on_its_own(self) -> bool:
        """True for a product that no RenderSettings targets (catalog R2-4)."""
        return self.settings is None

    def effective(self, name: str) -> EffectiveValue:
        """The product's value if it is authored there (a block ``= None`` is not),
        otherwise the settings' composed value, authored or fallback (the
        product's fallback for a product rendered on its own)."""
        if self.product is not None:
            product = prim_values(self.product)
            if product.has_value(name):
                return EffectiveValue(product.authored(name), product.attribute(name), True)
        owner = prim_values(self.owner)
        return EffectiveValue(owner.composed(name), owner.attribute(name), owner.has_value(name))

    @cached_property
    def camera_relationship(self) -> Usd.Relationship:
        """The product's ``camera`` when it has a forwarded target (an empty
        ``rel camera = []`` cannot clear the settings camera), else the settings'."""
        if self.product is not None:
            product = prim_values(self.product)
            if self.settings is None or product.forwarded("camera"):
                return product.relationship("camera")
        return prim_values(self.owner).relationship("camera")

    @cached_property
    def camera_target(self) -> Target | None:
        """The first forwarded camera target, resolved; None when unset."""
        if self.product is not None:
            product = prim_values(self.product)
            if self.settings is None or product.forwarded("camera"):
                targets = product.targets("camera")
                return targets[0] if targets else None
        targets = prim_values(self.owner).targets("camera")
        return targets[0] if targets else None

    @cached_property
    def camera_prim(self) -> Usd.Prim | None:
        """The effective camera's prim when it is a usable Camera."""
        target = self.camera_target
        prim = target.usable_prim if target is not None else None
        if prim is None or not prim_values(prim).is_a(schemas.Camera):
            return None
        return prim

    @property
    def camera(self) -> UsdGeom.Camera | None:
        """The effective camera when it is a usable Camera prim, as the schema
        class (``camera_prim`` needs no import of UsdGeom's bindings)."""
        prim = self.camera_prim
        if prim is None:
            return None
        from pxr import UsdGeom  # its bindings cost start-up: only this API needs them

        return UsdGeom.Camera(prim)

    def describe(self) -> str:
        if self.settings is None:
            return f"product {self.owner.GetPath()} (rendered on its own)"
        if self.product is None:
            return f"settings {self.settings.GetPath()}"
        return f"settings {self.settings.GetPath()} with product {self.product.GetPath()}"


def settings_configurations(settings_prims: Iterable[Usd.Prim]) -> list[RenderConfiguration]:
    """Each usable RenderSettings with each usable product its ``products``
    targets (forwarded), or alone when it has none: ``UsdRenderComputeSpec``'s
    product loop (``pxr/usd/usdRender/spec.cpp``)."""
    configurations: list[RenderConfiguration] = []
    for settings in settings_prims:
        products = [
            t.prim
            for t in prim_values(settings).targets("products")
            if typed_target_problem(t, schemas.RenderProduct, "a RenderProduct") is None
        ]
        if products:
            configurations.extend(RenderConfiguration(settings, p) for p in products)
        else:
            configurations.append(RenderConfiguration(settings))
    return configurations


def renders_on_its_own(product: Usd.Prim) -> bool:
    """True when an untargeted product authors a camera of its own (a forwarded
    target), so renderers that address products by prim path (ovrtx, Kit's
    render products) can render it alone (catalog R2-4)."""
    return bool(prim_values(product).forwarded("camera"))


def own_configurations(untargeted_products: Iterable[Usd.Prim]) -> list[RenderConfiguration]:
    """A configuration for each of ``untargeted_products`` (usable products
    that no usable settings targets) that renders on its own (catalog R2-4)."""
    return [RenderConfiguration(None, p) for p in untargeted_products if renders_on_its_own(p)]
