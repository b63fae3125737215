"""What a rule is: metadata, hooks, and the diagnostics and fixes it yields.

A rule is a subclass of :class:`Rule` with explicit metadata and one or more
hooks that yield :class:`Diagnostic`. The engine stamps each diagnostic with the
rule's code, name and (configured) severity, and locates it in the layers.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any, ClassVar

from pxr import Sdf, Tf, Usd

from ..model import PROFILE_NAMES, Severity
from ..records import record
from .schemas import tf_type

if TYPE_CHECKING:
    from .context import Context

CODE_PATTERN = re.compile(r"^[A-Z]{1,4}[0-9]{3}$")
NAME_PATTERN = re.compile(r"^[a-z][a-z0-9]*(-[a-z0-9]+)*$")
FIX_SAFETY = ("safe", "safe-conditional", "unsafe", "none")
#: Names a renderer goes by that are not its profile's: its program (prman,
#: husk) or its settings' namespace (ri:, omni:rtx:, which profiles/detect.py reads).
_PROFILE_NICKNAMES = {
    "prman": "renderman",
    "hdprman": "renderman",
    "rman": "renderman",
    "ri": "renderman",
    "husk": "karma",
    "omni": "omniverse",
    "rtx": "omniverse",
}
#: Sections every rule docstring carries, in this order (ruff's layout).
DOC_SECTIONS = ("What it does", "Why is this bad?", "Example", "Use instead", "Fix safety")


@record(frozen=True, kw_only=True)
class Fix:
    """An automatic fix a rule offers; ``apply`` is required (the engine reports
    a Fix without one as the rule's error).

    ``apply`` receives the stage whose edit target the fixer has already set to
    ``layer`` (or, when that is None, to the layer of the finding). ``safe``
    fixes run with ``--fix``; unsafe ones (they may change what renders in a
    way the author did not mean) only with ``--unsafe-fixes``.
    """

    description: str
    safe: bool
    apply: Callable[[Usd.Stage], None] | None = None
    layer: Sdf.Layer | None = None


@record(frozen=True, kw_only=True)
class Diagnostic:
    """What a rule yields: a message anchored at a USD object.

    ``at`` is the prim, attribute or relationship the finding is about (None
    for the stage as a whole). ``layer`` overrides the layer the engine would
    pick (the strongest opinion on ``at``).
    """

    message: str
    at: Usd.Object | Sdf.Path | None = None
    fix: Fix | None = None
    layer: Sdf.Layer | None = None


def _schema_types(prim_types: object) -> bool:
    """Whether ``prim_types`` is what the engine dispatches on: checked when the
    class is defined, not per prim (a "RenderProduct" string failed every run
    with an internal error naming no rule)."""
    return isinstance(prim_types, (tuple, list)) and all(
        isinstance(schema, (Tf.Type, type)) and not tf_type(schema).isUnknown
        for schema in prim_types
    )


def profile_problem(profile: object) -> str | None:
    """Why a rule's ``profile`` names no renderer profile (None: it does, or is
    None). The engine runs a renderer rule only where its profile is judged
    present: a misspelt one ran nowhere, silently."""
    if profile is None or profile in PROFILE_NAMES:
        return None
    if not isinstance(profile, str):
        return f"profile {profile!r} is not a profile name (a str such as 'karma', or None)"
    import difflib  # only for an error

    key = profile.strip().lower()
    if key in ("", "auto"):  # auto chooses a profile per file: no rule's own
        return (
            f"profile {profile!r} is not a renderer profile: leave it None to run the rule "
            f"under every profile, or name one ({', '.join(PROFILE_NAMES)})"
        )
    near = _PROFILE_NICKNAMES.get(key) or (key if key in PROFILE_NAMES else None)
    near = near or difflib.get_close_matches(key, PROFILE_NAMES, n=1, cutoff=0)[0]
    return (
        f"profile {profile!r} is no renderer profile, so the rule would never run "
        f"(did you mean {near!r}? known: {', '.join(PROFILE_NAMES)})"
    )


def _options_problem(options: object) -> str | None:
    """What is wrong with a rule's ``Options`` (None: nothing, or no options)."""
    if options is None:
        return None
    if not isinstance(options, type):
        # is_dataclass holds for an instance too: the rule failed when it was made
        # (rules, check: "internal error: TypeError: ... is not callable").
        made = type(options).__name__
        return f"Options is an instance of {made}, not a dataclass (Options = {made})"
    if not dataclasses.is_dataclass(options):
        return "Options is not a dataclass"
    if required := _required_options(options):
        # The rule runs unconfigured too: a required field failed every such
        # run with an internal error naming neither the rule nor its plugin.
        return f"Options field(s) {', '.join(required)} have no default"
    return None


def _required_options(options: type) -> list[str]:
    """The fields of an ``Options`` dataclass that its constructor requires."""
    return [
        field.name
        for field in dataclasses.fields(options)
        if field.init
        and field.default is dataclasses.MISSING
        and field.default_factory is dataclasses.MISSING
    ]


class Rule:
    """Base class of every check.

    Subclasses set ``code``, ``name``, ``severity`` and, for ``check_prim``,
    ``prim_types`` (schema types such as ``schemas.RenderSettingsBase``, or schema
    classes such as ``UsdRender.SettingsBase``; the engine hands each prim only
    to the rules that asked for its type). Options are a
    frozen dataclass named ``Options`` nested in the rule. A base class that
    other rules share, with no code of its own, sets ``abstract = True``.
    """

    code: ClassVar[str]
    name: ClassVar[str]
    severity: ClassVar[Severity]
    prim_types: ClassVar[tuple[Tf.Type | type, ...]] = ()
    Options: ClassVar[type | None] = None
    #: The catalog's fix class: "safe", "safe-conditional", "unsafe" or "none".
    fix_safety: ClassVar[str] = "none"
    #: Other kebab-case names the rule answers to in selectors and suppressions.
    aliases: ClassVar[tuple[str, ...]] = ()
    #: True when the rule reads only render prims (RenderSettings, RenderProduct,
    #: RenderVar, RenderPass, the prims of its ``prim_types``), what their
    #: relationships target, and their ancestors. The engine then may compose
    #: only those (its fast path); one selected rule without it makes the engine
    #: compose the whole stage, so a rule always sees the stage it asks for.
    partial_composition: ClassVar[bool] = False
    #: True on a shared base class: not a rule, not validated or registered.
    abstract: ClassVar[bool] = False
    #: The renderer profile a renderer rule belongs to (``"karma"``): it runs
    #: only on configurations judged under that profile. None: every profile.
    profile: ClassVar[str | None] = None

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        # Only the class that says so is abstract: its subclasses are rules.
        cls.abstract = bool(cls.__dict__.get("abstract", False))
        if cls.abstract:
            return
        problems = []
        if not CODE_PATTERN.match(getattr(cls, "code", "")):
            problems.append(f"code {getattr(cls, 'code', None)!r} is not a prefix plus 3 digits")
        if not NAME_PATTERN.match(getattr(cls, "name", "")):
            problems.append(f"name {getattr(cls, 'name', None)!r} is not kebab-case")
        if not isinstance(getattr(cls, "severity", None), Severity):
            problems.append("severity is not a Severity")
        if cls.fix_safety not in FIX_SAFETY:
            problems.append(f"fix_safety {cls.fix_safety!r} is not one of {FIX_SAFETY}")
        if not _schema_types(cls.prim_types):
            problems.append(
                f"prim_types {cls.prim_types!r} is not a tuple of schema types "
                "(usdrender_lint.api.schemas) or schema classes (UsdRender.Product)"
            )
        if not cls.prim_types and cls.check_prim is not Rule.check_prim:
            # The engine hands check_prim only prims of prim_types: without them
            # the hook was silently never called and the rule found nothing.
            problems.append(
                "check_prim is never called: prim_types is empty (name the schema "
                "types it checks, e.g. (schemas.RenderProduct,))"
            )
        if (problem := _options_problem(cls.Options)) is not None:
            problems.append(problem)
        if (problem := profile_problem(cls.profile)) is not None:
            problems.append(problem)
        if not isinstance(cls.aliases, tuple) or not all(
            isinstance(alias, str) and NAME_PATTERN.match(alias) for alias in cls.aliases
        ):
            problems.append(f"aliases {cls.aliases!r} is not a tuple of kebab-case names")
        if not cls.documentation():
            # Its first line is what rules, SARIF and the editors show; explain prints it all.
            problems.append(
                "no docstring (the rule's documentation: its first line is the summary "
                "'rules' lists, and 'explain' prints it all)"
            )
        if problems:
            raise TypeError(f"rule class {cls.__qualname__}: " + "; ".join(problems))

    def __init__(self, options: Any = None) -> None:
        """``options``: an instance of the rule's ``Options`` (None: its defaults)."""
        if options is None and self.Options is not None:
            options = self.Options()
        elif self.Options is not None and not isinstance(options, self.Options):
            # A dict here failed later, inside the hook, as "'dict' object has no
            # attribute ...", far from the call that passed it.
            raise TypeError(
                f"{type(self).__qualname__} ({self.code}): options must be a "
                f"{type(self).__name__}.Options(...), got {type(options).__name__}"
            )
        self.options = options

    @classmethod
    def documentation(cls) -> str:
        """The rule's docstring: its own, else that of the nearest rule class it
        extends (a variant that changes only its code and name), never Rule's."""
        for klass in cls.__mro__:
            if klass is Rule:
                break
            doc = klass.__dict__.get("__doc__")
            if doc and doc.strip():
                return doc
        return ""

    @classmethod
    def summary(cls) -> str:
        """The first line of the docstring."""
        doc = cls.documentation().strip()
        return doc.splitlines()[0] if doc else ""

    def check_stage(self, ctx: Context) -> Iterable[Diagnostic]:
        """Called once per stage, after the traversal."""
        return ()

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterable[Diagnostic]:
        """Called for each usable prim of one of ``prim_types``."""
        return ()
