"""A finding that several configurations share is made once: the products of a
RenderSettings that inherit its dataWindowNDC, resolution or camera share its
attribute or relationship, and a rule yields one diagnostic for it (the engine
turned each copy into a finding, then dropped it as a duplicate)."""

from __future__ import annotations

from pxr import Usd
from rule_support import stage_from_text

from usdrender_lint.api import Diagnostic, Rule, schemas
from usdrender_lint.api.cache import LintCache, lint_cache
from usdrender_lint.api.context import Context
from usdrender_lint.rules.camera.ca003_camera_target_missing import CameraTargetMissing
from usdrender_lint.rules.camera.ca004_camera_target_not_camera import CameraTargetNotCamera
from usdrender_lint.rules.settings.se003_data_window_malformed import DataWindowMalformed
from usdrender_lint.rules.settings.se005_data_window_crop_or_overscan import (
    DataWindowCropOrOverscan,
)

PRODUCTS = ("a", "b", "c")


def _stage(settings_body: str) -> Usd.Stage:
    products = "".join(f'def RenderProduct "{name}"\n{{\n}}\n' for name in PRODUCTS)
    targets = ", ".join(f"</{name}>" for name in PRODUCTS)
    return stage_from_text(
        "#usda 1.0\n"
        f"{products}"
        'def Scope "NotACamera"\n{\n}\n'
        'def RenderSettings "S"\n{\n'
        f"    rel products = [{targets}]\n"
        f"    {settings_body}\n"
        "}\n"
    )


def _diagnostics(stage: Usd.Stage, rule: Rule) -> list[Diagnostic]:
    with lint_cache(LintCache(without_clips=True, without_varying=True)) as cache:
        ctx = Context(
            stage=stage,
            file="memory.usda",
            cache=cache,
            render_prims={
                schemas.RenderSettings: [stage.GetPrimAtPath("/S")],
                schemas.RenderProduct: [stage.GetPrimAtPath(f"/{n}") for n in PRODUCTS],
            },
        )
        return list(rule.check_stage(ctx))


def test_a_missing_camera_the_products_inherit_is_reported_once() -> None:
    stage = _stage("rel camera = </NoSuchCamera>")
    assert len(_diagnostics(stage, CameraTargetMissing())) == 1


def test_a_camera_target_that_is_no_camera_is_reported_once() -> None:
    stage = _stage("rel camera = </NotACamera>")
    assert len(_diagnostics(stage, CameraTargetNotCamera())) == 1


def test_a_window_the_products_inherit_is_reported_once() -> None:
    inverted = _stage("uniform float4 dataWindowNDC = (0.8, 0, 0.2, 1)")
    assert len(_diagnostics(inverted, DataWindowMalformed())) == 1
    cropped = _stage("uniform float4 dataWindowNDC = (0.1, 0.1, 0.9, 0.9)")
    assert len(_diagnostics(cropped, DataWindowCropOrOverscan())) == 1
