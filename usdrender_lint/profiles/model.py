"""What a renderer profile is: frozen data, no pxr, no I/O.

A profile states what one renderer reads and requires (catalog, Revision 2,
R2-5): the rules it switches off or judges at another severity, the prim
types it accepts where the schema expects a Camera, the types and tokens it
defines, and its own rule family. Every change carries the public source that
justifies it, so ``explain`` and the documentation site can show why.
"""

from __future__ import annotations

import fnmatch

from ..model import Severity
from ..records import record


@record(frozen=True, kw_only=True)
class RuleChange:
    """How a profile treats one generic rule: off (``severity`` None) or at
    another severity, and why, with the renderer's source."""

    code: str
    severity: Severity | None
    why: str
    source: str

    @property
    def off(self) -> bool:
        return self.severity is None

    def describe(self) -> str:
        what = "off" if self.off else f"severity {self.severity}"
        return f"{what}: {self.why} ({self.source})"


@record(frozen=True, kw_only=True)
class Accepted:
    """A name a renderer defines where the schema knows none: a prim type
    (``OmniLidar``, or a pattern such as ``Pxr*``), a productType token, or a
    prim path the application creates at run time; with why and the source."""

    name: str
    why: str
    source: str

    def matches(self, value: str) -> bool:
        name = self.name
        if "*" not in name and "?" not in name and "[" not in name:
            # No wildcard: fnmatch would compile (and cache) a pattern matching
            # this name alone, at each name's first use in a process.
            return value == name
        return fnmatch.fnmatchcase(value, name)


@record(frozen=True, kw_only=True)
class Behaviour:
    """What a renderer does about the condition a generic rule reports, where
    the rule's own wording (what the schema or ``UsdRenderComputeSpec`` does)
    says otherwise: a finding judged under the profile says this instead.
    ``what`` is a clause the rule puts in its message."""

    code: str
    what: str
    source: str


def _find(accepted: tuple[Accepted, ...], value: str) -> Accepted | None:
    return next((a for a in accepted if a.matches(value)), None)


@record(frozen=True, kw_only=True)
class Profile:
    """One renderer's profile; ``generic`` is the schema alone."""

    name: str
    description: str
    #: The two-letter code family of the profile's own rules ("" for none).
    family: str = ""
    #: Property namespaces whose authored properties on render prims are
    #: evidence of this renderer (``auto``), e.g. ``("karma:",)``.
    namespaces: tuple[str, ...] = ()
    #: Applied API schema name patterns that are evidence, e.g. ``("Karma*",)``.
    api_schemas: tuple[str, ...] = ()
    #: Prim path prefixes of scopes the renderer's application writes.
    scopes: tuple[str, ...] = ()
    #: The public sources that show the namespaces, API schemas and scopes
    #: above are the renderer's own.
    evidence_sources: tuple[str, ...] = ()
    changes: tuple[RuleChange, ...] = ()
    #: Prim types accepted where the schema expects a Camera (CA004).
    camera_types: tuple[Accepted, ...] = ()
    #: Camera paths the application creates at run time (CA003).
    runtime_cameras: tuple[Accepted, ...] = ()
    #: Prim types the renderer's schemas define (ST010).
    prim_types: tuple[Accepted, ...] = ()
    #: productType tokens the renderer renders besides the schema's (PR003).
    product_types: tuple[Accepted, ...] = ()
    #: Keys of the root layer's customLayerData (nested dictionaries joined
    #: with ":") that the renderer's application writes: evidence (``auto``).
    layer_data: tuple[Accepted, ...] = ()
    #: RenderVar properties that define the var's output in place of
    #: sourceName (VA001).
    var_outputs: tuple[Accepted, ...] = ()
    #: What the renderer does about a rule's condition where the rule's
    #: message would say otherwise (the rule keeps its severity unless
    #: ``changes`` says so).
    behaviours: tuple[Behaviour, ...] = ()

    def change_for(self, code: str) -> RuleChange | None:
        return next((c for c in self.changes if c.code == code), None)

    def behaviour_for(self, code: str) -> Behaviour | None:
        return next((b for b in self.behaviours if b.code == code), None)

    def camera_type(self, type_name: str) -> Accepted | None:
        return _find(self.camera_types, type_name)

    def runtime_camera(self, path: str) -> Accepted | None:
        return _find(self.runtime_cameras, path)

    def prim_type(self, type_name: str) -> Accepted | None:
        return _find(self.prim_types, type_name)

    def product_type(self, token: str) -> Accepted | None:
        return _find(self.product_types, token)

    def layer_datum(self, key: str) -> Accepted | None:
        return _find(self.layer_data, key)

    def var_output(self, property_name: str) -> Accepted | None:
        return _find(self.var_outputs, property_name)


@record(frozen=True)
class ProfileChoice:
    """The profile a configuration (or the stage) is judged under, and why."""

    profile: Profile
    reason: str

    @property
    def name(self) -> str:
        return self.profile.name


def judge(
    code: str,
    severity: Severity,
    rule_profile: str | None,
    choices: tuple[ProfileChoice, ...],
) -> tuple[ProfileChoice, Severity] | None:
    """Under which of ``choices`` a finding of rule ``code`` (default
    ``severity``) stands, and at what severity; None when no choice keeps it.

    A renderer rule (``rule_profile``) stands only under its own profile. A
    generic rule stands under every choice that does not switch it off; when
    a prim belongs to configurations of several profiles the strictest
    verdict wins, so no configuration loses a finding.
    """
    if rule_profile is not None:
        own = [c for c in choices if c.name == rule_profile]
        return (own[0], severity) if own else None
    best: tuple[ProfileChoice, Severity] | None = None
    for choice in choices:
        change = choice.profile.change_for(code)
        level = severity if change is None else change.severity
        if level is None:
            continue
        if best is None or level.rank > best[1].rank:
            best = (choice, level)
    return best
