"""RenderMan's render terminals and camera projection, in both of their forms.

A RenderSettings names its integrator and its sample and display filters, and
a Camera its projection, either with attribute connections (the form of
`usdRiPxr`'s `PxrRenderTerminalsAPI` and `PxrCameraProjectionAPI` in OpenUSD
`third_party/renderman-26/plugin/usdRiPxr/schema.usda`:
`outputs:ri:integrator.connect`, ...) or with relationships (the form newer
RenderMan schemas register: `rel ri:integrator`, `rel ri:sampleFilters`,
`rel ri:displayFilters`, `rel ri:projection`). OpenUSD's usdImaging reads the
relationships when the registered RenderSettings schema declares
`ri:integrator`, and falls back to the connections (with a deprecation
warning) only when no relationship target was found
(`UsdImagingRenderSettingsAdapter::Populate`,
`pxr/usdImaging/usdImaging/renderSettingsAdapter.cpp`).
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from pxr import Sdf, Tf, Usd

from usdrender_lint.api import Context, Fix, record, schemas
from usdrender_lint.api.resolve import Target, authored_targets, describe_prim_type, resolve_target

#: The validators this module's RM003 / RM004 follow.
VALIDATORS_SRC = (
    "OpenUSD third_party/renderman-26/plugin/rmanUsdValidators (validators "
    "PxrRenderTerminalsAPIRelationships and PxrCameraProjectionAPIRelationships)"
)


@record(frozen=True)
class Terminal:
    """One RenderMan terminal: its relationship and its connection form."""

    #: "integrator", "sample filter", ...
    what: str
    relationship: str
    connection: str
    #: The usdRiPxr base class of the prims it may name.
    base: str
    #: True when the renderer takes one target (the first) of several.
    single: bool = False

    def effect(self) -> str:
        if self.single:
            return "renders with RenderMan's default integrator"
        return f"renders without that {self.what}"


INTEGRATOR = Terminal(
    "integrator", "ri:integrator", "outputs:ri:integrator", "PxrIntegratorPluginBase", True
)
TERMINALS = (
    INTEGRATOR,
    Terminal(
        "sample filter", "ri:sampleFilters", "outputs:ri:sampleFilters", "PxrSampleFilterPluginBase"
    ),
    Terminal(
        "display filter",
        "ri:displayFilters",
        "outputs:ri:displayFilters",
        "PxrDisplayFilterPluginBase",
    ),
)
PROJECTION = Terminal(
    "projection", "ri:projection", "outputs:ri:projection", "PxrProjectionPluginBase", True
)


@record(frozen=True)
class Form:
    """The targets one form of a terminal names on a prim."""

    terminal: Terminal
    #: The relationship or the attribute.
    prop: Usd.Property
    #: Prim paths, in the order the renderer reads them.
    paths: tuple[Sdf.Path, ...]

    @property
    def is_relationship(self) -> bool:
        return isinstance(self.prop, Usd.Relationship)

    def describe(self) -> str:
        return "relationship" if self.is_relationship else "connection"


def relationship_form(prim: Usd.Prim, terminal: Terminal) -> Form | None:
    """The terminal's relationship on ``prim`` when it has targets."""
    rel = prim.GetRelationship(terminal.relationship)
    paths = tuple(p.GetPrimPath() for p in authored_targets(rel)) if rel else ()
    return Form(terminal, rel, paths) if paths else None


def connection_form(prim: Usd.Prim, terminal: Terminal) -> Form | None:
    """The terminal's attribute on ``prim`` when it has connections."""
    attr = prim.GetAttribute(terminal.connection)
    if not attr or not attr.HasAuthoredConnections():
        return None
    paths = tuple(p.GetPrimPath() for p in attr.GetConnections())
    return Form(terminal, attr, paths) if paths else None


def forms(prim: Usd.Prim, terminal: Terminal) -> Iterator[Form]:
    for form in (relationship_form(prim, terminal), connection_form(prim, terminal)):
        if form is not None:
            yield form


def target_problem(stage: Usd.Stage, path: Sdf.Path, terminal: Terminal) -> str | None:
    """Why the prim at ``path`` cannot be the terminal's target, phrased to
    follow the path; None when it can or when nothing here can tell.

    usdImaging populates a target only through the prim adapter of its type
    (``_GetPrimAdapter`` in the adapter above), which RenderMan registers for
    its usdRiPxr types: a missing or unusable prim, a typeless one, or one
    whose type is registered but not derived from the terminal's usdRiPxr
    base is never a terminal. A type the registry does not know (RenderMan's
    own where RenderMan is not installed) is given the benefit of the doubt.
    """
    target: Target = resolve_target(stage, path)
    if not target.ok or target.prim is None:
        return target.problem
    prim = target.prim
    type_name = prim.GetTypeName()
    if not type_name:
        return f"is a typeless prim, not a RenderMan {terminal.what}"
    prim_type = Usd.SchemaRegistry.GetTypeFromName(type_name)
    if prim_type == Tf.Type.Unknown:
        return None
    base = Usd.SchemaRegistry.GetTypeFromName(terminal.base)
    if base != Tf.Type.Unknown and prim_type.IsA(base):
        return None
    return f"is {describe_prim_type(prim)}, not a RenderMan {terminal.what}"


def relationship_schema_registered(schema: str, relationship: str) -> bool:
    """Whether the schema registry where the linter runs declares
    ``relationship`` on ``schema`` (a concrete type or an applied API)."""
    registry = Usd.SchemaRegistry()
    definition = registry.FindConcretePrimDefinition(schema) or (
        registry.FindAppliedAPIPrimDefinition(schema)
    )
    return bool(definition and definition.GetRelationshipDefinition(relationship))


def relationship_form_evidence(ctx: Context) -> str | None:
    """What says this stage's RenderMan expects the relationship form, or None.

    The validators report the connection form only where the registered
    schema has the relationship form; a RenderMan that registers it also
    writes it, so a relationship-form terminal authored on this stage (on a
    RenderSettings or a render camera) says the same for the whole stage.
    """
    return ctx.cached(_relationship_form_evidence)


def _relationship_form_evidence(ctx: Context) -> str | None:
    if relationship_schema_registered("RenderSettings", INTEGRATOR.relationship):
        return "the registered RenderSettings schema declares rel ri:integrator"
    if relationship_schema_registered("PxrCameraProjectionAPI", PROJECTION.relationship):
        return "the registered PxrCameraProjectionAPI declares rel ri:projection"
    for settings in ctx.prims_of(schemas.RenderSettings):
        for terminal in TERMINALS:
            if relationship_form(settings, terminal) is not None:
                return f"<{settings.GetPath()}> authors rel {terminal.relationship}"
    for config in ctx.configurations:
        camera = config.camera_prim
        if camera is not None and relationship_form(camera, PROJECTION) is not None:
            return f"<{camera.GetPath()}> authors rel {PROJECTION.relationship}"
    return None


def convert_to_relationship(prim_path: Sdf.Path, terminal: Terminal) -> Any:
    """A fix: the terminal's connections become its relationship's targets
    (the connected prims), and the connections are removed, in the edit
    target's layer; the attribute's spec goes when nothing else is left on it,
    and an override layer over a weaker connection authors an empty one."""

    def apply(stage: Usd.Stage) -> None:
        prim = stage.GetPrimAtPath(prim_path)
        attr = prim.GetAttribute(terminal.connection)
        paths = list(dict.fromkeys(p.GetPrimPath() for p in attr.GetConnections()))
        rel = prim.CreateRelationship(terminal.relationship, custom=False)
        rel.SetTargets(paths)
        attr.ClearConnections()
        if attr.HasAuthoredConnections():
            # A weaker layer connects too (the edit target is an override
            # layer): an explicit empty list silences it.
            attr.SetConnections([])
            return
        spec = stage.GetEditTarget().GetPropertySpecForScenePath(attr.GetPath())
        if spec is not None and _only_declares(spec):
            spec.owner.RemoveProperty(spec)

    return apply


def _only_declares(spec: Sdf.PropertySpec) -> bool:
    """A spec left with no value, no connections and no metadata beyond its
    type: what a connection statement leaves once its targets are gone."""
    keys = set(spec.ListInfoKeys()) - {"typeName", "custom", "variability"}
    return not keys


def conversion_fix(form: Form, safe: bool) -> Fix:
    targets = ", ".join(f"<{p}>" for p in form.paths)
    return Fix(
        description=f"author rel {form.terminal.relationship} = [{targets}] and remove the "
        f"connection {form.terminal.connection}",
        safe=safe,
        apply=convert_to_relationship(form.prop.GetPrim().GetPath(), form.terminal),
    )
