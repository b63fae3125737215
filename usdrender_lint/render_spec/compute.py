"""What a stage will render: the render specification of each RenderSettings,
computed from the stage ``check`` linted (its Context, so every target and
value is resolved once, by :mod:`usdrender_lint.api.resolve`).

The semantics are ``UsdRenderComputeSpec``'s (``pxr/usd/usdRender/spec.cpp``),
which usd-core does not wrap for Python. In its order: the settings' values
with fallbacks form a base product; each product target that is a
RenderProduct starts from it and overrides the values it authors (not its
fallbacks); the camera is the product's first forwarded ``camera`` target, else
the settings'; its apertures are read and ``_ApplyAspectRatioPolicy`` conforms
them; then productType, productName and the ordered vars (dataType,
sourceName, sourceType, and every other namespaced attribute as
namespacedSettings). One difference, by design (catalog R2-1): the camera and
productName are read at the rendered time, not at Default; what
``UsdRenderComputeSpec`` gives instead is recorded beside (``ComputeSpecView``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import field, replace
from typing import Any

from pxr import Gf, Sdf, Usd, UsdGeom, UsdRender, UsdShade

from ..api import Context
from ..api.resolve import (
    DEFAULT_TIME,
    RenderConfiguration,
    composed_value,
    fallback_value,
    has_authored_value,
    items,
    rendered_times,
    resolve_targets,
    typed_target_problem,
)
from ..engine import InspectionError
from ..engine.locate import locate
from ..model import Finding
from ..records import record
from .data import (
    ComputeSpecView,
    FileSpec,
    Framing,
    ProductSpec,
    SettingsSpec,
    Source,
    Time,
    VarSpec,
)
from .framing import apply_aspect_ratio_policy, data_window, screen_window

#: The camera attributes the specification reads (R2-1: their samples decide
#: the rendered times).
CAMERA_ATTRIBUTES = (
    "horizontalAperture",
    "verticalAperture",
    "horizontalApertureOffset",
    "verticalApertureOffset",
    "projection",
    "focalLength",
    "shutter:open",
    "shutter:close",
)


class SpecError(InspectionError):
    """The specification asked for cannot be computed for this file (one line)."""


@record(frozen=True)
class SpecOptions:
    """What ``spec`` is asked for: a time (None: the stage's startTimeCode
    when authored, else each camera's first rendered time), Default
    explicitly (``--time default``), or one settings prim."""

    time: float | None = None
    default_time: bool = False
    settings: str | None = None


def settings_profile(ctx: Context, settings: Usd.Prim) -> tuple[str, str]:
    """The renderer profile a RenderSettings is judged under (catalog R2-5)
    and why: the lint's choice for its scope, ``generic`` without profiles."""
    choice = ctx.profile_of(RenderConfiguration(settings))
    if choice is None:
        return "generic", "the linter ran without profiles"
    return choice.name, choice.reason


def compute_file_spec(ctx: Context, findings: Sequence[Finding], options: SpecOptions) -> FileSpec:
    """The specification of every usable RenderSettings of the linted stage,
    the stage's ``renderSettingsPrimPath`` one first (``primary``)."""
    stage = ctx.stage
    time, time_from = requested_time(stage, options)
    primary = UsdRender.Settings.GetStageRenderSettings(stage)
    primary_path = primary.GetPath() if primary else None
    prims = list(ctx.prims_of(UsdRender.Settings))
    prims.sort(key=lambda p: p.GetPath() != primary_path)  # stable: the rest keep stage order
    if options.settings is not None:
        prims = [p for p in prims if str(p.GetPath()) == options.settings]
        if not prims:
            raise SpecError(f"no usable RenderSettings at <{options.settings}>")
    reader = _Reader(ctx, time, at_default=options.default_time)
    settings = tuple(reader.settings_spec(prim, prim.GetPath() == primary_path) for prim in prims)
    metadata = stage.GetMetadata("renderSettingsPrimPath") or None
    return FileSpec(time, time_from, metadata, settings)


def requested_time(stage: Usd.Stage, options: SpecOptions) -> tuple[Time, str]:
    if options.default_time:
        return None, "--time"
    if options.time is not None:
        return options.time, "--time"
    if stage.HasAuthoredMetadata("startTimeCode"):
        return stage.GetStartTimeCode(), "startTimeCode"
    return None, "default"


def _time_code(time: Time) -> Usd.TimeCode:
    return DEFAULT_TIME if time is None else Usd.TimeCode(time)


def _time_value(time: Usd.TimeCode) -> Time:
    return None if time.IsDefault() else time.GetValue()


class _Reader:
    """Reads the specification of one stage at one requested time."""

    def __init__(self, ctx: Context, time: Time, at_default: bool = False) -> None:
        self.ctx = ctx
        self.stage = ctx.stage
        self.time = time
        #: ``--time default``: everything at Default, sampled or not.
        self.at_default = at_default
        self.cap = ctx.time_sample_cap

    # -- settings ------------------------------------------------------------

    def settings_spec(self, prim: Usd.Prim, primary: bool) -> SettingsSpec:
        configurations = [c for c in self.ctx.configurations if c.settings == prim]
        products = tuple(self.product_spec(c) for c in configurations if c.product is not None)
        sources = {
            name: self._source(prim.GetAttribute(name), "settings")
            for name in ("includedPurposes", "materialBindingPurposes", "renderingColorSpace")
        }
        color_space = composed_value(prim, "renderingColorSpace")
        profile, why = settings_profile(self.ctx, prim)
        return SettingsSpec(
            path=str(prim.GetPath()),
            primary=primary,
            profile=profile,
            profile_reason=why,
            included_purposes=_strings(composed_value(prim, "includedPurposes")),
            material_binding_purposes=_strings(composed_value(prim, "materialBindingPurposes")),
            rendering_color_space=str(color_space) if color_space is not None else None,
            namespaced_settings=namespaced_settings(prim),
            sources=sources,
            base=self.product_spec(RenderConfiguration(prim)),
            products=products,
        )

    # -- products ------------------------------------------------------------

    def product_spec(self, config: RenderConfiguration) -> ProductSpec:
        """A configuration's product, or with no product the settings' own
        values (spec.cpp's base product)."""
        product = config.product
        sources: dict[str, Source] = {}
        values = self._settings_base(config, sources)
        resolution = (int(values["resolution"][0]), int(values["resolution"][1]))
        pixel_aspect = float(values["pixelAspectRatio"])
        policy = str(values["aspectRatioConformPolicy"])
        ndc = tuple(float(c) for c in items(values["dataWindowNDC"]))
        disable_blur = bool(values["disableMotionBlur"])

        target = config.camera_target
        # Judged as CA003 and CA004 judge it: a camera the profile's
        # application creates at run time is no problem, and has no values here.
        runtime = self.ctx.runtime_camera(config)
        at_run_time = None if runtime is None else (runtime[0].name, runtime[1].why)
        camera_problem = None if runtime is not None else _camera_problem(config)
        if target is not None:
            rel = config.camera_relationship
            own = product is not None and rel.GetPrim() == product
            sources["camera"] = self._source(rel, "product" if own else "settings")
        camera = _Camera(None, self.time, (), None, None, None)
        if (
            target is not None
            and target.prim is not None
            and camera_problem is None
            and runtime is None
        ):
            camera, camera_sources = self.ctx.cached(
                _read_camera, self, target.prim, resolution, pixel_aspect, policy
            )
            sources.update(camera_sources)
            if disable_blur:
                # The schema: disableMotionBlur sets the camera's shutter to [0, 0].
                camera = replace(camera, shutter=(0.0, 0.0))

        outputs = _Outputs()
        if product is not None:
            outputs = self._outputs(product, camera.time, sources)
        return ProductSpec(
            path=str(product.GetPath()) if product is not None else None,
            name=outputs.name,
            type=outputs.type,
            camera=str(target.path) if target is not None else None,
            camera_problem=camera_problem,
            camera_at_run_time=at_run_time,
            time=camera.time,
            rendered_times=camera.rendered_times,
            resolution=resolution,
            pixel_aspect_ratio=(
                camera.framing.conformed.pixel_aspect_ratio
                if camera.framing is not None
                else pixel_aspect
            ),
            aspect_ratio_conform_policy=policy,
            framing=camera.framing,
            data_window_ndc=(ndc[0], ndc[1], ndc[2], ndc[3]),
            data_window=data_window((ndc[0], ndc[1], ndc[2], ndc[3]), resolution),
            disable_motion_blur=disable_blur,
            disable_depth_of_field=bool(values["disableDepthOfField"]),
            shutter=camera.shutter,
            vars=outputs.vars,
            namespaced_settings=outputs.namespaced_settings,
            sources=sources,
            owners=_owners(config, outputs),
            compute_spec=self._compute_spec_view(config, camera, outputs, at_run_time),
        )

    def _settings_base(
        self, config: RenderConfiguration, sources: dict[str, Source]
    ) -> dict[str, Any]:
        """The RenderSettingsBase values of a configuration: the product's
        where it authors them, else the settings', authored or fallback."""
        values = {}
        for name in (
            "resolution",
            "pixelAspectRatio",
            "aspectRatioConformPolicy",
            "dataWindowNDC",
            "disableMotionBlur",
            "disableDepthOfField",
        ):
            effective = config.effective(name)
            values[name] = effective.value
            kind = "fallback"
            if effective.authored:
                own = config.product is not None and effective.attr.GetPrim() == config.product
                kind = "product" if own else "settings"
            sources[name] = self._source(effective.attr, kind)
        return values

    def camera(
        self, prim: Usd.Prim, resolution: tuple[int, int], pixel_aspect: float, policy: str
    ) -> tuple[_Camera, dict[str, Source]]:
        """The camera read at the product's camera time: the time asked for;
        without one (no startTimeCode, no --time), its first rendered time
        (R2-1: Default is not rendered when a camera input is sampled)."""
        attrs = [prim.GetAttribute(n) for n in CAMERA_ATTRIBUTES]
        times = rendered_times(attrs, self.cap)
        time = self.time
        if time is None and not self.at_default:
            time = _time_value(times[0])
        sources = {attr.GetName(): self._source(attr, "camera") for attr in attrs}
        read = _camera_reader(prim, _time_code(time))
        camera = _Camera(
            time=time,
            rendered_times=tuple(_time_value(t) for t in times),
            framing=_framing(read, resolution, pixel_aspect, policy),
            framing_at_default=_framing(
                _camera_reader(prim, DEFAULT_TIME), resolution, pixel_aspect, policy
            ),
            shutter=(float(read("shutter:open")), float(read("shutter:close"))),
            prim=prim,
        )
        return camera, sources

    def _outputs(self, product: Usd.Prim, time: Time, sources: dict[str, Source]) -> _Outputs:
        """productName (at ``time``; at Default, the first time it is
        rendered), productType, the ordered vars, the namespaced settings."""
        name_attr = product.GetAttribute("productName")
        if time is None and not self.at_default:
            time = _time_value(rendered_times([name_attr], self.cap)[0])
        sources["name"] = self._source(name_attr, "product")
        sources["type"] = self._source(product.GetAttribute("productType"), "product")
        return _Outputs(
            name=str(composed_value(product, "productName", _time_code(time)) or ""),
            name_at_default=str(composed_value(product, "productName") or ""),
            type=str(composed_value(product, "productType") or ""),
            vars=tuple(self._vars(product)),
            namespaced_settings=namespaced_settings(product),
        )

    def _compute_spec_view(
        self,
        config: RenderConfiguration,
        camera: _Camera,
        outputs: _Outputs,
        at_run_time: tuple[str, str] | None,
    ) -> ComputeSpecView:
        if config.product is None:
            return ComputeSpecView(
                False, "gives products only; these are the values its products start from"
            )
        target = config.camera_target
        # spec.cpp: UsdGeomCamera(stage->GetPrimAtPath(camPath)), else "Could not find camera".
        if target is None or target.prim is None or not target.prim.IsA(UsdGeom.Camera):
            where = f"<{target.path}>" if target is not None else "<>"
            reason = f"drops the product: could not find camera {where}"
            if at_run_time is not None:
                reason += (
                    f" on the stage as saved (under the {at_run_time[0]} profile the "
                    "application creates it at run time)"
                )
            return ComputeSpecView(False, reason)
        differs: dict[str, Any] = {}
        now, then = camera.framing, camera.framing_at_default
        if now is not None and then is not None:
            if not _same(then.aperture, now.aperture):
                differs["aperture.camera"] = list(then.aperture)
            if not _same(then.conformed.aperture, now.conformed.aperture):
                differs["aperture.conformed"] = list(then.conformed.aperture)
            ratio = then.conformed.pixel_aspect_ratio
            if not _same((ratio,), (now.conformed.pixel_aspect_ratio,)):
                differs["pixelAspectRatio"] = ratio
        if outputs.name_at_default != outputs.name:
            differs["name"] = outputs.name_at_default
        return ComputeSpecView(True, None, differs)

    # -- vars ------------------------------------------------------------------

    def _vars(self, product: Usd.Prim) -> Iterable[VarSpec]:
        """The product's ordered vars, in order (forwarded targets are unique);
        targets that are no usable RenderVar are skipped (spec.cpp: "Skipping")."""
        for target in resolve_targets(product.GetRelationship("orderedVars")):
            if typed_target_problem(target, UsdRender.Var, "a RenderVar") is not None:
                continue
            prim = target.prim
            assert prim is not None  # a usable RenderVar
            yield VarSpec(
                path=str(target.path),
                name=prim.GetName(),
                data_type=str(composed_value(prim, "dataType")),
                source_name=str(composed_value(prim, "sourceName")),
                source_type=str(composed_value(prim, "sourceType")),
                namespaced_settings=namespaced_settings(prim),
            )

    # -- sources ---------------------------------------------------------------

    def _source(self, prop: Usd.Property, kind: str) -> Source:
        """Where the value of ``prop`` comes from: its strongest opinion's layer
        and line, or the schema fallback when it authors none. Once per property
        and lint: products share their settings' and their camera's."""
        return self.ctx.cached(_find_source, prop, kind)


def _find_source(ctx: Context, prop: Usd.Property, kind: str) -> Source:
    path = str(prop.GetPath()) if prop else None
    if isinstance(prop, Usd.Relationship):
        authored = bool(prop.GetTargets())
    else:
        authored = has_authored_value(prop)
    if not authored:
        return Source("fallback", path)
    where = locate(ctx.stage, ctx.file, prop)
    return Source(kind, path, where.layer, where.line)


@record(frozen=True)
class _Camera:
    """What a product reads from its camera (all None without one)."""

    prim: Usd.Prim | None
    time: Time
    rendered_times: tuple[Time, ...]
    framing: Framing | None
    framing_at_default: Framing | None
    shutter: tuple[float, float] | None


@record(frozen=True)
class _Outputs:
    """What a product alone holds (all None for the settings' base values)."""

    name: str | None = None
    name_at_default: str | None = None
    type: str | None = None
    vars: tuple[VarSpec, ...] = ()
    namespaced_settings: Mapping[str, Any] = field(default_factory=dict)


def _framing(
    read: Callable[[str], Any], resolution: tuple[int, int], pixel_aspect: float, policy: str
) -> Framing:
    aperture = (float(read("horizontalAperture")), float(read("verticalAperture")))
    offset = (float(read("horizontalApertureOffset")), float(read("verticalApertureOffset")))
    projection = str(read("projection"))
    conformed = apply_aspect_ratio_policy(resolution, pixel_aspect, aperture, policy)
    return Framing(
        aperture=aperture,
        offset=offset,
        conformed=conformed,
        screen_window=screen_window(conformed.aperture, offset, projection),
        projection=projection,
        focal_length=float(read("focalLength")),
    )


def _read_camera(
    ctx: Context,
    reader: _Reader,
    prim: Usd.Prim,
    resolution: tuple[int, int],
    pixel_aspect: float,
    policy: str,
) -> tuple[_Camera, dict[str, Source]]:
    # Once per camera and conform inputs: the products of a settings share both.
    return reader.camera(prim, resolution, pixel_aspect, policy)


def _owners(config: RenderConfiguration, outputs: _Outputs) -> tuple[str, ...]:
    """The prims whose values the product's spec shows: the settings, the product
    and its vars, the camera."""
    owners = [str(config.owner.GetPath())]
    if config.product is not None:
        owners.append(str(config.product.GetPath()))
        owners.extend(v.path for v in outputs.vars)
    if config.camera_target is not None:
        owners.append(str(config.camera_target.path))
    return tuple(dict.fromkeys(owners))


def _camera_problem(config: RenderConfiguration) -> str | None:
    target = config.camera_target
    if target is None:
        if config.product is None:
            return "the settings have no camera"
        return "neither the product nor its settings has a camera"
    problem = typed_target_problem(target, UsdGeom.Camera, "a Camera")
    return None if problem is None else f"<{target.path}> {problem}"


def _camera_reader(camera: Usd.Prim, time: Usd.TimeCode) -> Callable[[str], Any]:
    """Composed camera values at ``time``: the authored value, else the schema
    fallback (a blocked sample reads as the fallback, as typed C++ reads do)."""

    def read(name: str) -> Any:
        value = composed_value(camera, name, time)
        return fallback_value(camera, name) if value is None else value

    return read


def _same(a: Sequence[float], b: Sequence[float]) -> bool:
    """Equal values, a NaN equal to a NaN: the same NaN read at two times is
    no difference (``nan != nan`` would report one)."""
    return all(x == y or (math.isnan(x) and math.isnan(y)) for x, y in zip(a, b, strict=True))


def _strings(value: Any) -> tuple[str, ...]:
    return tuple(str(v) for v in items(value)) if value is not None else ()


# -- namespaced settings -----------------------------------------------------------


def namespaced_settings(prim: Usd.Prim) -> dict[str, Any]:
    """Every authored attribute whose name has a namespace (after ``outputs:``),
    by name: a connected ``outputs:`` attribute gives the paths of the prims
    producing its value, any other its value at Default
    (``_ReadNamespacedSettings``, ``pxr/usd/usdRender/spec.cpp``)."""
    found: dict[str, Any] = {}
    for attr in prim.GetAuthoredAttributes():
        name = attr.GetName()
        output = UsdShade.Output(attr) if name.startswith("outputs:") else None
        base = output.GetBaseName() if output else name
        if ":" not in base:
            continue
        if output:
            producers = UsdShade.Utils.GetValueProducingAttributes(output)
            if producers:
                found[name] = [str(a.GetPrim().GetPath()) for a in producers]
                continue
        value = attr.Get()
        if value is not None:
            found[name] = json_value(value)
    return dict(sorted(found.items()))  # a VtDictionary is ordered by key


def json_value(value: Any) -> Any:
    """A USD value as JSON-ready data: vectors, matrices and arrays as lists,
    paths and asset paths as strings, a time code as a number; a float that is
    not finite as None (JSON has no NaN)."""
    if value is None or isinstance(value, bool | int | str):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, Sdf.AssetPath):
        return value.path
    if isinstance(value, Sdf.Path):
        return str(value)
    if isinstance(value, Sdf.TimeCode):
        return json_value(float(value))
    if isinstance(value, Mapping):
        return {str(k): json_value(v) for k, v in value.items()}
    if isinstance(value, Gf.Quatd | Gf.Quatf | Gf.Quath):
        return [json_value(value.GetReal()), *json_value(value.GetImaginary())]
    try:
        elements = items(value)  # Gf vectors and matrices (by row), Vt arrays, lists
    except TypeError:
        return str(value)
    return [json_value(v) for v in elements]
