"""The plugin surface: everything a rule, built-in or third-party, needs.

A rule is a subclass of :class:`Rule` with explicit metadata and one or more
hooks that yield :class:`Diagnostic`. The engine stamps each diagnostic with the
rule's code, name and (configured) severity, and locates it in the layers.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, ClassVar

from pxr import Sdf, Usd, UsdRender

from .model import Severity
from .resolve import RenderConfiguration, render_configurations

__all__ = [
    "Context",
    "Diagnostic",
    "Fix",
    "FullStageRequired",
    "Rule",
    "Severity",
    "DOC_SECTIONS",
]

CODE_PATTERN = re.compile(r"^[A-Z]{1,4}[0-9]{3}$")
NAME_PATTERN = re.compile(r"^[a-z][a-z0-9]*(-[a-z0-9]+)*$")
FIX_SAFETY = ("safe", "safe-conditional", "unsafe", "none")
#: Context.memo's marker for a key not computed yet (None is a value).
_MISSING = object()
#: Sections every rule docstring carries, in this order (ruff's layout).
DOC_SECTIONS = ("What it does", "Why is this bad?", "Example", "Use instead", "Fix safety")


@dataclass
class Fix:
    """An automatic fix a rule offers.

    ``apply`` receives the stage whose edit target the fixer has already set to
    ``layer`` (or, when that is None, to the layer of the finding).
    """

    description: str
    safe: bool
    apply: Callable[[Usd.Stage], None] | None = None
    layer: Sdf.Layer | None = None


@dataclass
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


class Rule:
    """Base class of every check.

    Subclasses set ``code``, ``name``, ``severity`` and, for ``check_prim``,
    ``prim_types`` (schema classes such as ``UsdRender.SettingsBase``; the engine
    hands each prim only to the rules that asked for its type). Options are a
    frozen dataclass named ``Options`` nested in the rule.
    """

    code: ClassVar[str]
    name: ClassVar[str]
    severity: ClassVar[Severity]
    prim_types: ClassVar[tuple[type, ...]] = ()
    Options: ClassVar[type | None] = None
    #: The catalog's fix class: "safe", "safe-conditional", "unsafe" or "none".
    fix_safety: ClassVar[str] = "none"

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        problems = []
        if not CODE_PATTERN.match(getattr(cls, "code", "")):
            problems.append(f"code {getattr(cls, 'code', None)!r} is not a prefix plus 3 digits")
        if not NAME_PATTERN.match(getattr(cls, "name", "")):
            problems.append(f"name {getattr(cls, 'name', None)!r} is not kebab-case")
        if not isinstance(getattr(cls, "severity", None), Severity):
            problems.append("severity is not a Severity")
        if cls.fix_safety not in FIX_SAFETY:
            problems.append(f"fix_safety {cls.fix_safety!r} is not one of {FIX_SAFETY}")
        if cls.Options is not None and not dataclasses.is_dataclass(cls.Options):
            problems.append("Options is not a dataclass")
        if problems:
            raise TypeError(f"rule class {cls.__qualname__}: " + "; ".join(problems))

    def __init__(self, options: Any = None) -> None:
        if options is None and self.Options is not None:
            options = self.Options()
        self.options = options

    @classmethod
    def summary(cls) -> str:
        """The first line of the docstring."""
        return (cls.__doc__ or "").strip().splitlines()[0] if cls.__doc__ else ""

    def check_stage(self, ctx: Context) -> Iterable[Diagnostic]:
        """Called once per stage, after the traversal."""
        return ()

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterable[Diagnostic]:
        """Called for each usable prim of one of ``prim_types``."""
        return ()


class FullStageRequired(Exception):
    """Raised by :meth:`Context.require_full_stage` on a partly composed stage;
    the engine catches it and lints the file again, fully composed."""


@dataclass
class Context:
    """What the engine knows about the stage being linted, shared by all rules.

    Derived data (render configurations, memoised helpers) is computed once per
    stage, on first use.
    """

    stage: Usd.Stage
    file: str
    #: Usable render prims found by the traversal, keyed by schema class.
    render_prims: dict[type, list[Usd.Prim]] = field(default_factory=dict)
    #: Usable prims whose non-empty type name no registered schema defines.
    unknown_type_prims: list[Usd.Prim] = field(default_factory=list)
    #: Cap on the authored time samples a rule evaluates.
    time_sample_cap: int = 1000
    #: True when the engine composed only the render prims, what they target
    #: and their ancestors (its fast path; see fastpath.py).
    partial: bool = False
    _memo: dict[Any, Any] = field(default_factory=dict, repr=False)

    def require_full_stage(self) -> None:
        """Call before reading beyond the render prims, their targets and
        ancestors (e.g. walking every prim): on a partly composed stage it
        makes the engine lint the file again, fully composed."""
        if self.partial:
            raise FullStageRequired

    def prims_of(self, schema: type) -> list[Usd.Prim]:
        return self.render_prims.get(schema, [])

    @cached_property
    def configurations(self) -> list[RenderConfiguration]:
        """Every (settings, product) render configuration on the stage."""
        return render_configurations(self.prims_of(UsdRender.Settings))

    @cached_property
    def untargeted_products(self) -> list[Usd.Prim]:
        """Usable RenderProducts that no RenderSettings' ``products`` targets."""
        targeted = {c.product.GetPath() for c in self.configurations if c.product is not None}
        return [p for p in self.prims_of(UsdRender.Product) if p.GetPath() not in targeted]

    def memo(self, key: Any, compute: Callable[[], Any]) -> Any:
        """Compute a per-stage value once and share it between rules."""
        # One lookup on a hit: keys hold USD objects, whose hashing is not free.
        value = self._memo.get(key, _MISSING)
        if value is _MISSING:
            value = self._memo[key] = compute()
        return value
