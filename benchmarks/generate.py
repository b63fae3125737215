"""Deterministic synthetic shots for the performance benchmark and the fast-path tests.

A *shot* is laid out the way production shots are: a shot layer that sublayers a
lighting and a layout layer, the layout referencing asset files whose geometry
sits behind a payload, plus a little unique set dressing. The shot layer holds
the camera and the render prims (``/Render``). With ``defects`` it also holds
known render-settings mistakes, and ``expected_findings.json`` next to it lists
the findings they must produce. ``many`` writes a folder of small shot files,
the load a CI gate sees.

Everything is a pure function of the arguments: the same call writes the same
files. Run ``python benchmarks/generate.py --help``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

from pxr import Gf, Sdf, Vt

FORMATS = ("usda", "usdc")
#: Distinct asset files the layout instances reference.
ASSET_KINDS = 12
#: Prims each asset's payload holds: PARTS groups of MESHES_PER_PART meshes.
PARTS, MESHES_PER_PART = 8, 7
ASSET_PRIMS = 1 + PARTS * (1 + MESHES_PER_PART)  # composed prims per instance
#: Share of the shot's prims that are unique set dressing in the layout layer.
DRESSING_SHARE = 0.05
EXPECTED_FILE = "expected_findings.json"

_TRIANGLE_POINTS = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (1.0, 1.0, 0.0)]


@dataclass(frozen=True)
class Expected:
    """A finding an injected defect must produce."""

    code: str
    path: str

    def as_dict(self) -> dict[str, str]:
        return {"code": self.code, "path": self.path}


# -- Sdf helpers ------------------------------------------------------------------


def _prim(layer: Sdf.Layer, path: str, type_name: str = "", specifier=Sdf.SpecifierDef):
    spec = Sdf.CreatePrimInLayer(layer, path)
    spec.specifier = specifier
    if type_name:
        spec.typeName = type_name
    return spec


def _attr(spec: Sdf.PrimSpec, name: str, type_name, value, uniform: bool = False):
    variability = Sdf.VariabilityUniform if uniform else Sdf.VariabilityVarying
    attr = Sdf.AttributeSpec(spec, name, type_name, variability)
    if value is not None:
        attr.default = value
    return attr


def _rel(spec: Sdf.PrimSpec, name: str, targets: list[str]) -> None:
    rel = Sdf.RelationshipSpec(spec, name)
    for target in targets:
        rel.targetPathList.explicitItems.append(Sdf.Path(target))


def _new_layer(path: Path) -> Sdf.Layer:
    path.parent.mkdir(parents=True, exist_ok=True)
    existing = Sdf.Layer.Find(str(path))
    if existing is not None:
        existing.Clear()
        return existing
    return Sdf.Layer.CreateNew(str(path))


def _mesh(layer: Sdf.Layer, path: str, index: int, purpose: str | None = None) -> None:
    mesh = _prim(layer, path, "Mesh")
    shift = float(index % 17)
    _attr(
        mesh,
        "points",
        Sdf.ValueTypeNames.Point3fArray,
        [(x + shift, y, z) for x, y, z in _TRIANGLE_POINTS],
    )
    _attr(mesh, "faceVertexCounts", Sdf.ValueTypeNames.IntArray, [4])
    _attr(mesh, "faceVertexIndices", Sdf.ValueTypeNames.IntArray, [0, 1, 3, 2])
    _attr(mesh, "extent", Sdf.ValueTypeNames.Float3Array, [(shift, 0, 0), (shift + 1, 1, 0)])
    color = _attr(
        mesh,
        "primvars:displayColor",
        Sdf.ValueTypeNames.Color3fArray,
        [((index % 5) / 4.0, 0.5, 0.25)],
    )
    color.SetInfo("interpolation", "constant")
    if purpose:
        _attr(mesh, "purpose", Sdf.ValueTypeNames.Token, purpose, uniform=True)


def _translate(spec: Sdf.PrimSpec, offset: tuple[float, float, float]) -> None:
    _attr(spec, "xformOp:translate", Sdf.ValueTypeNames.Double3, Gf.Vec3d(*offset))
    _attr(spec, "xformOpOrder", Sdf.ValueTypeNames.TokenArray, ["xformOp:translate"], uniform=True)


# -- assets -----------------------------------------------------------------------


def _write_asset(folder: Path, kind: int, fmt: str) -> str:
    """An asset file (referenced by the layout) whose geometry is a payload."""
    name = f"asset_{kind:02d}"
    geo = _new_layer(folder / f"{name}_geo.{fmt}")
    with Sdf.ChangeBlock():
        root = _prim(geo, f"/{name}", "Xform")
        geo.defaultPrim = root.name
        for part in range(PARTS):
            group = f"/{name}/part_{part}"
            _prim(geo, group, "Xform")
            for mesh in range(MESHES_PER_PART):
                purpose = "proxy" if mesh == 0 else ("render" if mesh == 1 else None)
                _mesh(geo, f"{group}/mesh_{mesh}", kind * 100 + part * 10 + mesh, purpose)
    geo.Save()

    asset = _new_layer(folder / f"{name}.{fmt}")
    with Sdf.ChangeBlock():
        root = _prim(asset, f"/{name}", "Xform")
        asset.defaultPrim = root.name
        root.SetInfo("kind", "component")
        root.payloadList.prependedItems.append(Sdf.Payload(f"./{name}_geo.{fmt}"))
    asset.Save()
    return f"./assets/{name}.{fmt}"


# -- the shot ---------------------------------------------------------------------


def _write_layout(path: Path, fmt: str, instances: int, dressing: int) -> None:
    layer = _new_layer(path)
    with Sdf.ChangeBlock():
        _prim(layer, "/World", "Xform")
        _prim(layer, "/World/set", "Xform")
        for i in range(instances):
            inst = _prim(layer, f"/World/set/inst_{i:06d}", "Xform")
            inst.referenceList.prependedItems.append(
                Sdf.Reference(f"./assets/asset_{i % ASSET_KINDS:02d}.{fmt}")
            )
            _translate(inst, (float(i % 100) * 3.0, 0.0, float(i // 100) * 3.0))
        _prim(layer, "/World/dressing", "Xform")
        per_group = 50
        for g in range(math.ceil(dressing / (per_group + 1))):
            group = f"/World/dressing/grp_{g:05d}"
            _prim(layer, group, "Xform")
            for m in range(min(per_group, dressing - g * (per_group + 1) - 1)):
                _mesh(layer, f"{group}/prop_{m}", g * per_group + m)
    layer.Save()


def _write_lighting(path: Path, lights: int) -> None:
    layer = _new_layer(path)
    with Sdf.ChangeBlock():
        _prim(layer, "/World", "Xform", Sdf.SpecifierOver)
        _prim(layer, "/World/lights", "Xform")
        for i in range(lights):
            light = _prim(
                layer, f"/World/lights/light_{i:04d}", "SphereLight" if i % 2 else "RectLight"
            )
            _attr(light, "inputs:intensity", Sdf.ValueTypeNames.Float, 10.0 + i)
            _attr(light, "inputs:exposure", Sdf.ValueTypeNames.Float, 1.0)
            _translate(light, (float(i), 10.0, 0.0))
    layer.Save()


def _write_camera(layer: Sdf.Layer) -> None:
    if not layer.GetPrimAtPath("/World"):
        _prim(layer, "/World", "Xform", Sdf.SpecifierOver)
    _prim(layer, "/World/cams", "Xform")
    cam = _prim(layer, "/World/cams/shotCam", "Camera")
    _attr(cam, "focalLength", Sdf.ValueTypeNames.Float, 35.0)
    _attr(cam, "horizontalAperture", Sdf.ValueTypeNames.Float, 36.0)
    _attr(cam, "verticalAperture", Sdf.ValueTypeNames.Float, 20.25)
    _attr(cam, "clippingRange", Sdf.ValueTypeNames.Float2, Gf.Vec2f(0.1, 10000.0))
    translate = _attr(cam, "xformOp:translate", Sdf.ValueTypeNames.Double3, None)
    for frame in range(1001, 1025):
        layer.SetTimeSample(translate.path, frame, Gf.Vec3d(0.0, 1.5, float(frame - 1000)))
    _attr(cam, "xformOpOrder", Sdf.ValueTypeNames.TokenArray, ["xformOp:translate"], uniform=True)
    _prim(layer, "/World/cams/camRig", "Xform")
    rig_cam = _prim(layer, "/World/cams/camRig/cam", "Camera")
    _attr(rig_cam, "focalLength", Sdf.ValueTypeNames.Float, 50.0)


#: (name, sourceName, dataType) of the vars every generated shot has.
_BASE_VARS = (("color", "Ci", "color3f"), ("alpha", "a", "float"), ("depth", "z", "float"))


def _write_vars(layer: Sdf.Layer, specs: tuple[tuple[str, str, str], ...]) -> list[str]:
    """Raw RenderVars under /Render/Vars, one per (name, sourceName, dataType); their paths."""
    names = Sdf.ValueTypeNames
    _prim(layer, "/Render/Vars", "Scope")
    paths = []
    for name, source, data_type in specs:
        var = _prim(layer, f"/Render/Vars/{name}", "RenderVar")
        _attr(var, "sourceName", names.String, source, uniform=True)
        _attr(var, "dataType", names.Token, data_type, uniform=True)
        _attr(var, "sourceType", names.Token, "raw", uniform=True)
        paths.append(var.path.pathString)
    return paths


def _write_render(layer: Sdf.Layer, defects: bool) -> list[Expected]:
    """The render prims; with ``defects``, the mistakes and their findings."""
    names = Sdf.ValueTypeNames
    _prim(layer, "/Render", "Scope")
    _write_vars(layer, _BASE_VARS)
    _prim(layer, "/Render/Products", "Scope")
    beauty = _prim(layer, "/Render/Products/beauty", "RenderProduct")
    _attr(beauty, "productName", names.Token, "beauty.exr")
    _rel(beauty, "orderedVars", ["/Render/Vars/color", "/Render/Vars/alpha", "/Render/Vars/depth"])

    settings = _prim(layer, "/Render/Settings", "RenderSettings")
    _attr(settings, "resolution", names.Int2, Gf.Vec2i(1920, 1080), uniform=True)
    _attr(settings, "pixelAspectRatio", names.Float, 1.0, uniform=True)
    _attr(settings, "aspectRatioConformPolicy", names.Token, "expandAperture", uniform=True)
    _attr(settings, "includedPurposes", names.TokenArray, ["default", "render"], uniform=True)
    _attr(settings, "materialBindingPurposes", names.TokenArray, ["full", ""], uniform=True)
    _rel(settings, "camera", ["/World/cams/shotCam"])
    products = ["/Render/Products/beauty"]

    _prim(layer, "/Render/Passes", "Scope")
    render_pass = _prim(layer, "/Render/Passes/lights", "RenderPass")
    _attr(render_pass, "passType", names.Token, "prman", uniform=True)
    _rel(render_pass, "renderSource", ["/Render/Settings"])
    _rel(render_pass, "collection:renderVisibility:includes", ["/World/lights"])

    expected: list[Expected] = []
    if defects:
        broken = _prim(layer, "/Render/Products/broken", "RenderProduct")
        _attr(broken, "productName", names.Token, "broken.exr")
        _attr(broken, "dataWindowNDC", names.Float4, Gf.Vec4f(0.8, 0.0, 0.2, 1.0), uniform=True)
        products.append(broken.path.pathString)
        expected += [
            Expected("SE003", "/Render/Products/broken.dataWindowNDC"),
            Expected("PR004", "/Render/Products/broken"),
        ]
        rig = _prim(layer, "/Render/RigSettings", "RenderSettings")
        _attr(rig, "resolution", names.Int2, Gf.Vec2i(1920, 1080), uniform=True)
        _attr(rig, "aspectRatioConformPolicy", names.Token, "expandAperture", uniform=True)
        _rel(rig, "camera", ["/World/cams/camRig"])
        _rel(rig, "products", ["/Render/Products/beauty"])
        expected.append(Expected("CA004", "/Render/RigSettings.camera"))
        lost = _prim(layer, "/Render/LostSettings", "RenderSettings")
        _rel(lost, "camera", ["/World/cams/noSuchCam"])
        _rel(lost, "products", ["/Render/Products/beauty"])
        expected.append(Expected("CA003", "/Render/LostSettings.camera"))
    _rel(settings, "products", products)
    return expected


def _shot_layer(path: Path, sublayers: list[str], defects: bool) -> list[Expected]:
    layer = _new_layer(path)
    with Sdf.ChangeBlock():
        layer.subLayerPaths[:] = sublayers
        layer.pseudoRoot.SetInfo("renderSettingsPrimPath", "/Render/Settings")
        layer.startTimeCode, layer.endTimeCode = 1001, 1024
        _write_camera(layer)
        expected = _write_render(layer, defects)
    layer.Save()
    return expected


def _write_expected(folder: Path, by_file: dict[str, list[Expected]]) -> None:
    data = {name: [e.as_dict() for e in found] for name, found in sorted(by_file.items())}
    (folder / EXPECTED_FILE).write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")


def shot_plan(prims: int) -> tuple[int, int, int]:
    """(instances, dressing prims, lights) for a shot of about ``prims`` prims."""
    dressing = int(prims * DRESSING_SHARE)
    lights = max(3, prims // 2000)
    instances = max(1, round((prims - dressing - lights) / (ASSET_PRIMS + 1)))
    return instances, dressing, lights


def generate_shot(folder: str | Path, prims: int, fmt: str = "usdc", defects: bool = True) -> Path:
    """Write a shot of about ``prims`` composed prims into ``folder``; return
    the shot layer. ``expected_findings.json`` lists the injected defects'
    findings (empty without ``defects``)."""
    if fmt not in FORMATS:
        raise ValueError(f"format must be one of {FORMATS}, got {fmt!r}")
    folder = Path(folder)
    instances, dressing, lights = shot_plan(prims)
    for kind in range(min(ASSET_KINDS, instances)):
        _write_asset(folder / "assets", kind, fmt)
    _write_layout(folder / f"layout.{fmt}", fmt, instances, dressing)
    _write_lighting(folder / f"lighting.{fmt}", lights)
    shot = folder / f"shot.{fmt}"
    expected = _shot_layer(shot, [f"./lighting.{fmt}", f"./layout.{fmt}"], defects)
    _write_expected(folder, {shot.name: expected})
    return shot


def generate_flat_shot(folder: str | Path, prims: int, defects: bool = True) -> Path:
    """Write a one-file shot: the layered shot of about ``prims`` prims (see
    generate_shot) flattened into ``shot.usdc``, a single layer with no arcs to
    other layers. ``expected_findings.json`` lists the same defects' findings."""
    from pxr import Usd

    folder = Path(folder)
    layered = generate_shot(folder / "layered", prims, "usdc", defects)
    flat = folder / "shot.usdc"
    Usd.Stage.Open(str(layered)).Export(str(flat))
    expected = json.loads((folder / "layered" / EXPECTED_FILE).read_text(encoding="utf-8"))
    (folder / EXPECTED_FILE).write_text(
        json.dumps({flat.name: expected[layered.name]}, indent=2) + "\n", encoding="utf-8"
    )
    return flat


def _small_shot(path: Path, index: int, prims: int, defects: bool) -> list[Expected]:
    """A self-contained shot file: a camera, render prims and flat geometry."""
    layer = _new_layer(path)
    with Sdf.ChangeBlock():
        layer.pseudoRoot.SetInfo("renderSettingsPrimPath", "/Render/Settings")
        _prim(layer, "/World", "Xform")
        _write_camera(layer)
        _prim(layer, "/World/lights", "Xform")
        _prim(layer, "/World/lights/key", "DistantLight")
        expected = _write_render(layer, defects)
        budget = max(0, prims - 20)
        per_group = 9
        for g in range(math.ceil(budget / (per_group + 1))):
            group = f"/World/geo/grp_{g:03d}"
            _prim(layer, group, "Xform")
            for m in range(min(per_group, budget - g * (per_group + 1) - 1)):
                _mesh(layer, f"{group}/mesh_{m}", index + g * per_group + m)
    layer.Save()
    return expected


def generate_many(
    folder: str | Path,
    count: int = 500,
    prims: int = 200,
    fmt: str = "usda",
    defect_every: int = 10,
) -> list[Path]:
    """Write ``count`` small shot files of about ``prims`` prims; every
    ``defect_every``-th has the injected defects (0: none)."""
    if fmt not in FORMATS:
        raise ValueError(f"format must be one of {FORMATS}, got {fmt!r}")
    folder = Path(folder)
    files, expected = [], {}
    for i in range(count):
        path = folder / f"shot_{i:04d}.{fmt}"
        defects = bool(defect_every) and i % defect_every == 0
        expected[path.name] = _small_shot(path, i, prims, defects)
        files.append(path)
    _write_expected(folder, expected)
    return files


def _gate_render(layer: Sdf.Layer, index: int) -> None:
    """The render prims of a CI-gate shot: 3 cameras, 6 vars, 12 products,
    4 RenderSettings and 4 passes, as a production shot file holds them; every
    tenth shot has two mistakes (a malformed data window, a missing camera)."""
    names = Sdf.ValueTypeNames
    _prim(layer, "/World/cams", "Xform")
    cameras = []
    for c, focal in enumerate((35.0, 50.0, 85.0)):
        cam = _prim(layer, f"/World/cams/cam{c}", "Camera")
        _attr(cam, "focalLength", names.Float, focal)
        _attr(cam, "horizontalAperture", names.Float, 36.0)
        _attr(cam, "verticalAperture", names.Float, 20.25)
        _attr(cam, "clippingRange", names.Float2, Gf.Vec2f(0.1, 10000.0))
        cameras.append(cam.path.pathString)
    _prim(layer, "/Render", "Scope")
    var_paths = _write_vars(
        layer,
        (*_BASE_VARS, ("normal", "N", "normal3f"), ("position", "P", "point3f"),
         ("albedo", "albedo", "color3f")),
    )  # fmt: skip
    _prim(layer, "/Render/Products", "Scope")
    products = []
    for p in range(12):
        product = _prim(layer, f"/Render/Products/out{p:02d}", "RenderProduct")
        _attr(product, "productName", names.Token, f"shot{index:04d}.out{p:02d}.####.exr")
        _rel(product, "orderedVars", var_paths[: 2 + p % 5])
        if p % 3 == 0:
            _rel(product, "camera", [cameras[p % 3]])
            _attr(product, "resolution", names.Int2, Gf.Vec2i(2048, 858), uniform=True)
        products.append(product.path.pathString)
    settings_paths = []
    for s in range(4):
        settings = _prim(layer, f"/Render/Settings{s}", "RenderSettings")
        _attr(settings, "resolution", names.Int2, Gf.Vec2i(1920, 1080), uniform=True)
        _attr(settings, "pixelAspectRatio", names.Float, 1.0, uniform=True)
        _attr(settings, "aspectRatioConformPolicy", names.Token, "expandAperture", uniform=True)
        _attr(settings, "includedPurposes", names.TokenArray, ["default", "render"], uniform=True)
        _attr(settings, "materialBindingPurposes", names.TokenArray, ["full", ""], uniform=True)
        broken = index % 10 == 0 and s == 3
        _rel(settings, "camera", ["/World/cams/noSuchCam" if broken else cameras[s % 3]])
        _rel(settings, "products", products[s * 3 : s * 3 + 3])
        if broken:
            _attr(settings, "dataWindowNDC", names.Float4, Gf.Vec4f(0.8, 0, 0.2, 1), uniform=True)
        settings_paths.append(settings.path.pathString)
    _prim(layer, "/Render/Passes", "Scope")
    for r in range(4):
        render_pass = _prim(layer, f"/Render/Passes/pass{r}", "RenderPass")
        _attr(render_pass, "passType", names.Token, "prman", uniform=True)
        _rel(render_pass, "renderSource", [settings_paths[r]])
        _rel(render_pass, "collection:renderVisibility:includes", ["/World/geo"])
    layer.pseudoRoot.SetInfo("renderSettingsPrimPath", settings_paths[0])


def _gate_shot(path: Path, index: int, prims: int) -> None:
    """A CI-gate shot file: the render prims of :func:`_gate_render` and about
    ``prims`` scene prims (groups of meshes)."""
    layer = _new_layer(path)
    with Sdf.ChangeBlock():
        _prim(layer, "/World", "Xform")
        _gate_render(layer, index)
        _prim(layer, "/World/geo", "Xform")
        budget = max(0, prims - 5)
        per_group = 9
        for g in range(math.ceil(budget / (per_group + 1))):
            group = f"/World/geo/grp_{g:03d}"
            _prim(layer, group, "Xform")
            for m in range(min(per_group, budget - g * (per_group + 1) - 1)):
                _mesh(layer, f"{group}/mesh_{m}", index + g * per_group + m)
    layer.Save()


def generate_gate(
    folder: str | Path, count: int = 200, prims: int = 200, fmt: str = "usda"
) -> list[Path]:
    """Write ``count`` CI-gate shots (see :func:`_gate_shot`) as ``.usda`` (or ``fmt``)."""
    folder = Path(folder)
    files = []
    for i in range(count):
        path = folder / f"gate_{i:04d}.{fmt}"
        _gate_shot(path, i, prims)
        files.append(path)
    return files


def generate_purposes(folder: str | Path, count: int, fmt: str = "usdc") -> Path:
    """One RenderSettings whose includedPurposes lists "default" ``count``
    times: hostile content (issue 13) whose message must be bounded."""
    path = Path(folder) / f"purposes_{count}.{fmt}"
    path.parent.mkdir(parents=True, exist_ok=True)
    layer = _new_layer(path)
    settings = _prim(layer, "/Render/Settings", "RenderSettings")
    _prim(layer, "/Render", "Scope")
    _attr(
        settings,
        "includedPurposes",
        Sdf.ValueTypeNames.TokenArray,
        Vt.TokenArray(["default"] * count),
        uniform=True,
    )
    layer.Save()
    return path


def generate_variant_sets(folder: str | Path, count: int) -> Path:
    """One RenderSettings with ``count`` variant sets of two variants each,
    none selected: --variants must not cost more per set (issue 13)."""
    path = Path(folder) / f"variant_sets_{count}.usda"
    path.parent.mkdir(parents=True, exist_ok=True)
    layer = _new_layer(path)
    _prim(layer, "/Render", "Scope")
    settings = _prim(layer, "/Render/Settings", "RenderSettings")
    with Sdf.ChangeBlock():
        for index in range(count):
            variant_set = Sdf.VariantSetSpec(settings, f"set{index}")
            Sdf.VariantSpec(variant_set, "a")
            Sdf.VariantSpec(variant_set, "b")
        settings.variantSetNameList.prependedItems = [f"set{i}" for i in range(count)]
    layer.Save()
    return path


#: What each variant set of :func:`generate_variant_shot` changes on the
#: settings: (attribute, type, authored variant's value, other variant's value).
_VARIANT_EDITS = (
    ("resolution", "Int2", Gf.Vec2i(1920, 1080), Gf.Vec2i(4096, 1716)),
    ("pixelAspectRatio", "Float", 1.0, 0.0),
    ("aspectRatioConformPolicy", "Token", "expandAperture", "cropAperture"),
    ("dataWindowNDC", "Float4", Gf.Vec4f(0.0, 0.0, 1.0, 1.0), Gf.Vec4f(0.8, 0.0, 0.2, 1.0)),
    ("disableMotionBlur", "Bool", False, True),
    ("instantaneousShutter", "Bool", False, True),
)


def generate_variant_shot(folder: str | Path, prims: int, sets: int = 6) -> Path:
    """The flat shot of about ``prims`` prims (see generate_flat_shot) whose
    RenderSettings has ``sets`` variant sets (at most six) of two variants
    each, the first selected: 2^sets combinations for --variants, some of
    whose other variants hold a defect (a zero pixel aspect ratio, a
    malformed data window)."""
    if not 1 <= sets <= len(_VARIANT_EDITS):
        raise ValueError(f"sets must be 1 to {len(_VARIANT_EDITS)}, got {sets}")
    flat = generate_flat_shot(folder, prims, defects=False)
    layer = Sdf.Layer.FindOrOpen(str(flat))
    settings = layer.GetPrimAtPath("/Render/Settings")
    names = Sdf.ValueTypeNames
    with Sdf.ChangeBlock():
        for index, (name, type_name, *values) in enumerate(_VARIANT_EDITS[:sets]):
            if name in settings.attributes:  # a local opinion would beat the variants'
                settings.RemoveProperty(settings.attributes[name])
            variant_set = Sdf.VariantSetSpec(settings, f"look{index}")
            for variant, value in zip(("a", "b"), values, strict=True):
                spec = Sdf.VariantSpec(variant_set, variant).primSpec
                _attr(spec, name, getattr(names, type_name), value, uniform=True)
            settings.variantSelections[f"look{index}"] = "a"
        settings.variantSetNameList.prependedItems = [f"look{i}" for i in range(sets)]
    layer.Save()
    return flat


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="what", required=True)
    flat = sub.add_parser("flat", help="one shot flattened into a single .usdc")
    flat.add_argument("folder")
    flat.add_argument("--prims", type=int, default=100_000)
    flat.add_argument("--clean", action="store_true", help="no injected defects")
    shot = sub.add_parser("shot", help="one layered shot")
    shot.add_argument("folder")
    shot.add_argument("--prims", type=int, default=100_000)
    shot.add_argument("--format", choices=FORMATS, default="usdc")
    shot.add_argument("--clean", action="store_true", help="no injected defects")
    many = sub.add_parser("many", help="a folder of small shot files")
    many.add_argument("folder")
    many.add_argument("--count", type=int, default=500)
    many.add_argument("--prims", type=int, default=200)
    many.add_argument("--format", choices=FORMATS, default="usda")
    many.add_argument(
        "--defect-every", type=int, default=10, help="every Nth file has defects (0: none)"
    )
    gate = sub.add_parser("gate", help="a folder of CI-gate shots (many render prims each)")
    gate.add_argument("folder")
    gate.add_argument("--count", type=int, default=200)
    gate.add_argument("--prims", type=int, default=200)
    gate.add_argument("--format", choices=FORMATS, default="usda")
    purposes = sub.add_parser("purposes", help="includedPurposes listing 'default' COUNT times")
    purposes.add_argument("folder")
    purposes.add_argument("--count", type=int, default=2_000_000)
    purposes.add_argument("--format", choices=FORMATS, default="usdc")
    variant_sets = sub.add_parser("variant-sets", help="a RenderSettings with COUNT variant sets")
    variant_sets.add_argument("folder")
    variant_sets.add_argument("--count", type=int, default=10_000)
    variant_shot = sub.add_parser(
        "variant-shot", help="the flat shot with variant sets on its RenderSettings"
    )
    variant_shot.add_argument("folder")
    variant_shot.add_argument("--prims", type=int, default=100_000)
    variant_shot.add_argument("--sets", type=int, default=6)
    args = parser.parse_args(argv)
    if args.what == "gate":
        made = generate_gate(args.folder, args.count, args.prims, args.format)
        print(f"{len(made)} files in {args.folder}")
    elif args.what == "purposes":
        print(generate_purposes(args.folder, args.count, args.format))
    elif args.what == "variant-shot":
        print(generate_variant_shot(args.folder, args.prims, args.sets))
    elif args.what == "variant-sets":
        print(generate_variant_sets(args.folder, args.count))
    elif args.what == "flat":
        print(generate_flat_shot(args.folder, args.prims, defects=not args.clean))
    elif args.what == "shot":
        print(generate_shot(args.folder, args.prims, args.format, defects=not args.clean))
    else:
        written = generate_many(args.folder, args.count, args.prims, args.format, args.defect_every)
        print(f"{len(written)} files in {args.folder}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
