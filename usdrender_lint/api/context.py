"""What a rule is handed: the stage being linted and what the engine knows of it."""

from __future__ import annotations

from collections.abc import Callable, Hashable
from dataclasses import field
from functools import cached_property
from typing import Any, TypeVar

from pxr import Sdf, Tf, Usd

from ..records import record
from . import schemas
from .cache import _MISSING, LintCache
from .resolve import (
    RenderConfiguration,
    own_configurations,
    settings_configurations,
    values_in,
)

_T = TypeVar("_T")


class FullStageRequired(Exception):
    """Raised by :meth:`Context.require_full_stage` on a partly composed stage;
    the engine catches it and lints the file again, fully composed."""


@record
class Context:
    """What the engine knows about the stage being linted, shared by all rules.

    Derived data (render configurations, cached helpers) is computed once per
    lint, on first use, and dropped with the lint.
    """

    stage: Usd.Stage
    file: str
    #: Usable render prims found by the traversal, keyed by schema class.
    render_prims: dict[Tf.Type, list[Usd.Prim]] = field(default_factory=dict)
    #: Usable prims whose non-empty type name no registered schema defines.
    unknown_type_prims: list[Usd.Prim] = field(default_factory=list)
    #: Cap on the authored time samples a rule evaluates.
    time_sample_cap: int = 1000
    #: True when the engine composed only the render prims, what they target
    #: and their ancestors (its fast path; see engine/partial.py).
    partial: bool = False
    #: This lint's cache (see :meth:`cached`).
    cache: LintCache = field(default_factory=LintCache, repr=False)
    #: The renderer profile of every configuration (R2-5), set by the engine
    #: when it lints with profiles (usdrender_lint.profiles.detect.Assignment):
    #: ``choices_for(path)``, ``for_scope(path)``, ``present()``, ``judge(...)``.
    #: None: no profiles, every finding judged by the schema alone.
    profiles: Any = None
    #: The asset values whose existence rules checked (:meth:`depends_on_asset`).
    asset_dependencies: list[tuple[Sdf.Layer | None, Sdf.AssetPath]] = field(
        default_factory=list, repr=False
    )
    #: How :attr:`composition_errors` is computed when not by asking the whole
    #: stage: --variants reuses the authored selections' errors where USD did
    #: not recompose (engine/variants.py).
    composition_errors_source: Callable[[], list] | None = field(default=None, repr=False)

    def depends_on_asset(self, value: Sdf.AssetPath, layer: Sdf.Layer | None) -> None:
        """Say that a finding (or its absence) depends on whether the asset
        ``value`` resolves, as authored in ``layer`` (the layer of the
        opinion, which anchors a relative path): a rule that checks an asset
        exists calls this, and a cached result is linted again once that file
        appears, disappears or resolves elsewhere."""
        self.asset_dependencies.append((layer, value))

    def require_full_stage(self) -> None:
        """Call before reading beyond the render prims, their targets and
        ancestors (e.g. walking every prim): on a partly composed stage it
        makes the engine lint the file again, fully composed."""
        if self.partial:
            raise FullStageRequired

    def prims_of(self, schema: Tf.Type | type) -> list[Usd.Prim]:
        """The usable prims of a render schema (RenderSettings, RenderProduct,
        RenderVar, RenderPass), named as ``schemas.RenderVar`` or ``UsdRender.Var``."""
        return self.render_prims.get(schemas.tf_type(schema), [])

    @cached_property
    def configurations(self) -> list[RenderConfiguration]:
        """Every render configuration on the stage: each (settings, product)
        pair, each settings without products, then each product rendered on
        its own (``settings`` None; catalog R2-4)."""
        return [*self._settings_configurations, *own_configurations(self.untargeted_products)]

    @cached_property
    def composition_errors(self) -> list:
        """``stage.GetCompositionErrors()``, asked once per lint (it walks the
        stage's prim indexes)."""
        if self.composition_errors_source is not None:
            return self.composition_errors_source()
        return list(self.stage.GetCompositionErrors())

    @cached_property
    def untargeted_products(self) -> list[Usd.Prim]:
        """Usable RenderProducts that no usable RenderSettings' ``products`` targets."""
        # A prim's PrimValues is one per lint, whichever handle asks: compared by
        # identity, no path is asked of a handle, hashed or compared.
        cache = self.cache
        targeted = {
            id(values_in(cache, c.product))
            for c in self._settings_configurations
            if c.product is not None
        }
        products = self.prims_of(schemas.RenderProduct)
        return [p for p in products if id(values_in(cache, p)) not in targeted]

    @cached_property
    def _settings_configurations(self) -> list[RenderConfiguration]:
        return settings_configurations(self.prims_of(schemas.RenderSettings))

    def profile_of(self, config: RenderConfiguration) -> Any:
        """The profile choice a render configuration is judged under (None
        without profiles)."""
        if self.profiles is None:
            return None
        # A product rendered on its own (R2-4) is a scope of its own.
        owner = config.settings if config.settings is not None else config.product
        return self.profiles.for_scope(owner.GetPath()) if owner is not None else None

    def profile_choices(self, at: Usd.Object | Sdf.Path | None) -> tuple[Any, ...]:
        """The profile choices a finding anchored at ``at`` is judged under
        (none without profiles)."""
        if self.profiles is None:
            return ()
        if isinstance(at, Usd.Object):
            at = at.GetPath()
        return tuple(self.profiles.choices_for(at))

    def behaviour(self, code: str, at: RenderConfiguration | Usd.Object | Sdf.Path) -> Any:
        """What the renderer does about rule ``code``'s condition (a profile's
        ``Behaviour``) for a finding about a configuration or at a prim, when
        every profile it is judged under says the same; else None, and the
        rule words its finding as the schema says."""
        if isinstance(at, RenderConfiguration):
            choice = self.profile_of(at)
            choices: tuple[Any, ...] = () if choice is None else (choice,)
        else:
            choices = self.profile_choices(at)
        found = None
        for choice in choices:
            behaviour = choice.profile.behaviour_for(code)
            if behaviour is None or found not in (None, behaviour):
                return None
            found = behaviour
        return found

    def profile_accepts(
        self, at: Usd.Object | Sdf.Path | None, kind: str, value: str
    ) -> tuple[Any, Any] | None:
        """When every profile a finding at ``at`` is judged under accepts
        ``value`` as ``kind`` ("camera_type", "runtime_camera", "prim_type"
        or "product_type"), the first of them and what it accepts; else None
        (a prim shared with a configuration that does not accept it keeps its
        finding)."""
        found = None
        # Without profiles nothing is accepted beyond the schema.
        for choice in self.profile_choices(at):
            accepted = getattr(choice.profile, kind)(value)
            if accepted is None:
                return None
            found = found or (choice, accepted)
        return found

    def runtime_camera(self, config: RenderConfiguration) -> tuple[Any, Any] | None:
        """When the configuration's camera is one the renderer's application
        creates at run time (a profile's ``runtime_cameras``, e.g. Kit's session
        cameras) and the stage holds nothing at its path but ``over``s that
        compose onto that camera (no prim at all, or a prim no layer defines,
        typeless or a Camera, active and not abstract): the profile choice and
        what it accepts (:meth:`profile_accepts`). Else None: a ``def`` (of any
        type), a typed ``over`` of another type or a deactivated one is judged
        as the schema says. CA003, CA004 and ``spec`` all ask this."""
        target = config.camera_target
        if target is None or target.path.IsPropertyPath():
            return None
        accepted = self.profile_accepts(
            config.camera_relationship, "runtime_camera", str(target.path)
        )
        if accepted is None:
            return None
        prim = target.prim
        if prim is None:
            return accepted
        if prim.HasDefiningSpecifier() or not prim.IsActive() or prim.IsAbstract():
            return None
        if prim.GetTypeName() and not prim.IsA(schemas.Camera):
            return None
        return accepted

    def accepted_names(self, at: Usd.Object | Sdf.Path | None, field_name: str) -> list[str]:
        """Every name the profiles at ``at`` accept in ``field_name`` (e.g.
        "camera_types"), for messages that say what else would do."""
        names: list[str] = []
        for choice in self.profile_choices(at):
            names.extend(a.name for a in getattr(choice.profile, field_name))
        return list(dict.fromkeys(names))

    def cached(self, func: Callable[..., _T], *args: Hashable) -> _T:
        """``func(self, *args)``, computed once per lint and shared between rules.
        The key is the function and the arguments: a module-level function
        makes a key no other helper can collide with."""
        if len(args) == 1 and type(args[0]) is Usd.Prim:
            # Keyed by the prim handle's identity (PrimValues): hashing a
            # Usd.Prim and comparing it on a hit are two binding calls.
            # (values_in and PrimValues.call inlined: 150 calls a shot.)
            prim = args[0]
            values = self.cache.by_identity.get(id(prim))
            if values is None:
                values = values_in(self.cache, prim)
            memo = values._memo
            answer = memo.get(func, _MISSING)
            if answer is _MISSING:
                answer = memo[func] = func(self, prim)
            return answer
        # LintCache.call without its call: some 300 a shot on a CI gate.
        answers = self.cache._answers
        key = (func, args)
        answer = answers.get(key, _MISSING)
        if answer is _MISSING:
            answer = answers[key] = func(self, *args)
        return answer
