"""What a rule is handed: the stage being linted and what the engine knows of it."""

from __future__ import annotations

from collections.abc import Callable, Hashable
from dataclasses import dataclass, field
from functools import cached_property
from typing import TypeVar

from pxr import Usd, UsdRender

from .cache import LintCache
from .resolve import RenderConfiguration, own_configurations, settings_configurations

_T = TypeVar("_T")


class FullStageRequired(Exception):
    """Raised by :meth:`Context.require_full_stage` on a partly composed stage;
    the engine catches it and lints the file again, fully composed."""


@dataclass
class Context:
    """What the engine knows about the stage being linted, shared by all rules.

    Derived data (render configurations, cached helpers) is computed once per
    lint, on first use, and dropped with the lint.
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
    #: and their ancestors (its fast path; see engine/partial.py).
    partial: bool = False
    #: This lint's cache (see :meth:`cached`).
    cache: LintCache = field(default_factory=LintCache, repr=False)

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
        """Every render configuration on the stage: each (settings, product)
        pair, each settings without products, then each product rendered on
        its own (``settings`` None; catalog R2-4)."""
        return [*self._settings_configurations, *own_configurations(self.untargeted_products)]

    @cached_property
    def untargeted_products(self) -> list[Usd.Prim]:
        """Usable RenderProducts that no usable RenderSettings' ``products`` targets."""
        targeted = {
            c.product.GetPath() for c in self._settings_configurations if c.product is not None
        }
        return [p for p in self.prims_of(UsdRender.Product) if p.GetPath() not in targeted]

    @cached_property
    def _settings_configurations(self) -> list[RenderConfiguration]:
        return settings_configurations(self.prims_of(UsdRender.Settings))

    def cached(self, func: Callable[..., _T], *args: Hashable) -> _T:
        """``func(self, *args)``, computed once per lint and shared between rules.
        The key is the function and the arguments: a module-level function
        makes a key no other helper can collide with."""
        return self.cache.call_with(func, self, args)
