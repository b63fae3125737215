"""api.schemas: the render schemas as Tf.Type handles, interchangeable with the
schema classes everywhere a rule names a schema (prim_types, Context.prims_of,
IsA), so third-party rules written against ``UsdRender.Var`` keep working."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from pxr import Sdf, Tf, Usd, UsdGeom, UsdRender

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import settings_configurations
from usdrender_lint.engine import Linter

SHOT = """#usda 1.0
def Camera "cam" {}
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel camera = </cam>
        rel products = </Render/Beauty>
    }
    def RenderProduct "Beauty"
    {
        rel orderedVars = </Render/Color>
    }
    def RenderVar "Color" {}
}
"""

PAIRS = [
    (schemas.RenderSettingsBase, UsdRender.SettingsBase),
    (schemas.RenderSettings, UsdRender.Settings),
    (schemas.RenderProduct, UsdRender.Product),
    (schemas.RenderVar, UsdRender.Var),
    (schemas.RenderPass, UsdRender.Pass),
    (schemas.Camera, UsdGeom.Camera),
]


@pytest.mark.parametrize(("handle", "cls"), PAIRS)
def test_each_handle_is_the_schema_class_type(handle: Tf.Type, cls: type) -> None:
    assert handle == Tf.Type.Find(cls)
    assert schemas.tf_type(handle) == schemas.tf_type(cls) == handle


def test_ordered_purposes_are_usdgeom_s() -> None:
    assert tuple(UsdGeom.Imageable.GetOrderedPurposeTokens()) == schemas.ORDERED_PURPOSES


def _stage(tmp_path) -> str:
    path = tmp_path / "shot.usda"
    path.write_text(SHOT)
    return str(path)


def _rule(prim_type: object, via: object) -> Rule:
    class Seen(Rule):
        """Reports each prim of ``prim_type`` and what ``prims_of(via)`` holds."""

        code = "XS001"
        name = "seen"
        severity = Severity.INFO
        prim_types = (prim_type,)

        def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
            listed = [str(p.GetPath()) for p in ctx.prims_of(via)]
            yield Diagnostic(message=f"{prim.GetPath()} of {listed}", at=prim)

    return Seen()


@pytest.mark.parametrize("prim_type", [schemas.RenderVar, UsdRender.Var])
@pytest.mark.parametrize("via", [schemas.RenderProduct, UsdRender.Product])
def test_prim_types_and_prims_of_take_either(tmp_path, prim_type, via) -> None:
    result = Linter([_rule(prim_type, via)]).lint_path(_stage(tmp_path))
    assert [f.message for f in result.findings] == ["/Render/Color of ['/Render/Beauty']"]


def test_camera_prim_and_the_schema_object_agree() -> None:
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(SHOT)
    stage = Usd.Stage.Open(layer)
    (config,) = settings_configurations([stage.GetPrimAtPath("/Render/Settings")])
    assert config.camera_prim == stage.GetPrimAtPath("/cam")
    camera = config.camera
    assert isinstance(camera, UsdGeom.Camera) and camera.GetPrim() == config.camera_prim
