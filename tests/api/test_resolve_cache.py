"""The per-lint cache: resolve.py's answers (and every rule's ctx.cached) live for
one lint only: a later lint of an edited stage, a nested lint and a call outside
any lint see fresh answers."""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from pxr import Gf, Sdf, Usd, UsdRender

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, resolve
from usdrender_lint.api.cache import LintCache, active_cache, lint_cache
from usdrender_lint.engine import Linter
from usdrender_lint.model import INTERNAL_ERROR_CODE
from usdrender_lint.testing import all_rules

SHOT = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        float2 resolution = (1920, 1080)
        uniform token aspectRatioConformPolicy = "expandAperture"
    }
}
"""


@pytest.fixture
def stage() -> Usd.Stage:
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(SHOT)
    return Usd.Stage.Open(layer)


def _settings(stage: Usd.Stage) -> Usd.Prim:
    return stage.GetPrimAtPath("/Render/Settings")


def _codes(findings) -> set[str]:
    return {f.code for f in findings if f.location.path == "/Render/Settings.resolution"}


def test_a_second_lint_sees_an_edited_type_and_value(stage) -> None:
    linter = Linter(all_rules(), raise_errors=True)
    assert "SE016" in _codes(linter.lint_stage(stage))  # float2 is not the schema's int2

    spec = stage.GetRootLayer().GetAttributeAtPath("/Render/Settings.resolution")
    spec.SetInfo("typeName", "int2")
    spec.default = Gf.Vec2i(-1, 1080)
    codes = _codes(linter.lint_stage(stage))
    assert "SE016" not in codes
    assert "SE001" in codes  # now authored, well typed and non-positive

    spec.SetInfo("typeName", "float2")
    assert _codes(linter.lint_stage(stage)) == {"SE016"}


def test_answers_are_memoised_inside_a_lint_memo_and_dropped_after(stage) -> None:
    attr = _settings(stage).GetAttribute("aspectRatioConformPolicy")
    with lint_cache():
        assert resolve.has_authored_value(attr)
        attr.Block()  # the engine never edits while rules run: the memo may answer
        assert resolve.has_authored_value(attr)
    assert not resolve.has_authored_value(attr)


def test_a_none_answer_is_remembered_inside_a_lint_memo(stage) -> None:
    attr = _settings(stage).GetAttribute("aspectRatioConformPolicy")
    with lint_cache():
        assert resolve.mismatched_spec(attr) is None  # token, as the schema declares
        spec = stage.GetRootLayer().GetAttributeAtPath(attr.GetPath())
        spec.SetInfo("typeName", "string")  # never during a lint: shows the memo answers
        assert resolve.mismatched_spec(attr) is None
    assert resolve.mismatched_spec(attr) is not None


def test_helpers_outside_a_lint_are_not_memoised(stage) -> None:
    assert active_cache() is None
    attr = _settings(stage).GetAttribute("resolution")
    assert resolve.mismatched_spec(attr) is not None
    assert not resolve.has_authored_value(attr)
    spec = stage.GetRootLayer().GetAttributeAtPath("/Render/Settings.resolution")
    spec.SetInfo("typeName", "int2")
    spec.default = Gf.Vec2i(640, 480)
    assert resolve.mismatched_spec(attr) is None
    assert resolve.has_authored_value(attr)
    assert resolve.composed_value(_settings(stage), "resolution") == Gf.Vec2i(640, 480)
    assert active_cache() is None


class _Probe(Rule):
    """Reads through resolve.py, records the memo it ran under, optionally raises.

    ## What it does
    ## Why is this bad?
    ## Example
    ## Use instead
    ## Fix safety
    """

    code = "ZZ901"
    name = "resolve-memo-probe"
    severity = Severity.INFO
    prim_types = (UsdRender.Settings,)
    memos: list[object] = []
    fail = False

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        resolve.has_authored_value(prim.GetAttribute("resolution"))
        type(self).memos.append(active_cache())
        if self.fail:
            raise RuntimeError("probe")
        yield from ()


@pytest.fixture
def probe() -> Iterator[type[_Probe]]:
    _Probe.memos, _Probe.fail = [], False
    yield _Probe


def test_each_lint_has_its_own_memo_and_drops_it(stage, probe) -> None:
    linter = Linter([probe()], raise_errors=True)
    linter.lint_stage(stage)
    linter.lint_stage(stage)
    first, second = probe.memos
    assert first is not None and second is not None and first is not second
    assert active_cache() is None


@pytest.mark.parametrize("raise_errors", [True, False])
def test_the_memo_is_dropped_when_a_rule_raises(stage, probe, raise_errors) -> None:
    probe.fail = True
    linter = Linter([probe()], raise_errors=raise_errors)
    if raise_errors:
        with pytest.raises(RuntimeError):
            linter.lint_stage(stage)
    else:
        assert [f.code for f in linter.lint_stage(stage)] == [INTERNAL_ERROR_CODE]
    assert probe.memos[0] is not None
    assert active_cache() is None


def test_a_nested_lint_uses_a_fresh_memo_and_restores_the_outer_one(stage, probe) -> None:
    inner = Linter([probe()], raise_errors=True)
    seen: list[object] = []

    class Outer(_Probe):
        code = "ZZ902"
        name = "resolve-memo-outer"

        def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
            seen.append(active_cache())
            inner.lint_stage(ctx.stage)
            seen.append(active_cache())
            yield from ()

    Linter([Outer()], raise_errors=True).lint_stage(stage)
    before, after = seen
    assert before is not None and after is before
    assert probe.memos[0] is not None and probe.memos[0] is not before


def test_the_memo_belongs_to_one_thread(stage) -> None:
    attr = _settings(stage).GetAttribute("aspectRatioConformPolicy")
    seen: list[object] = []
    with lint_cache():
        assert resolve.has_authored_value(attr)
        worker = threading.Thread(target=lambda: seen.append(active_cache()))
        worker.start()
        worker.join()
    assert seen == [None]


def test_an_empty_time_samples_opinion_holds_no_samples() -> None:
    # The stronger `.timeSamples = {}` must not hide the weaker layer's samples.
    weak = Sdf.Layer.CreateAnonymous(".usda")
    weak.ImportFromString(
        '#usda 1.0\nover "V"\n{\n    uniform token sourceType.timeSamples = {1: </X>}\n}\n'
    )
    strong = Sdf.Layer.CreateAnonymous(".usda")
    strong.ImportFromString(
        f'#usda 1.0\n(\n    subLayers = [@{weak.identifier}@]\n)\ndef RenderVar "V"\n'
        "{\n    uniform token sourceType.timeSamples = {}\n}\n"
    )
    stage = Usd.Stage.Open(strong)
    attr = stage.GetAttributeAtPath("/V.sourceType")
    assert attr.HasAuthoredValue()
    assert not resolve.has_authored_value(attr)  # the weaker samples hold a path


def test_schema_facts_follow_each_prims_type_and_applied_schemas() -> None:
    # Kept for the process per prim definition, so the key must tell these apart.
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(
        '#usda 1.0\ndef Scope "A" (prepend apiSchemas = ["CollectionAPI:x"])\n'
        '{\n    uniform string collection:x:expansionRule = "expandPrims"\n}\n'
        'def Scope "B"\n{\n    uniform string collection:x:expansionRule = "expandPrims"\n}\n'
        'def RenderVar "V" {}\n'
    )
    stage = Usd.Stage.Open(layer)
    a, b, v = (stage.GetPrimAtPath(p) for p in ("/A", "/B", "/V"))
    name = "collection:x:expansionRule"
    expansion = ("explicitOnly", "expandPrims", "expandPrimsAndProperties")
    for _ in range(2):
        with lint_cache():
            assert resolve.allowed_tokens(b, name) == ()
            assert resolve.allowed_tokens(a, name) == expansion
            assert "raw" in resolve.allowed_tokens(v, "sourceType")
            assert resolve.allowed_tokens(v, name) == ()
            assert resolve.mismatched_spec(a.GetAttribute(name)) is not None  # token in the API
            assert resolve.has_authored_value(b.GetAttribute(name))  # no schema: any type
    Usd.CollectionAPI.Apply(b, "x")
    with lint_cache():
        assert resolve.allowed_tokens(b, name) == expansion
        assert not resolve.has_authored_value(b.GetAttribute(name))


IS_A_SHOT = """#usda 1.0
(
    fallbackPrimTypes = {
        token[] FutureRenderVar = ["RenderVar"]
    }
)
def RenderSettings "S" {}
def RenderProduct "P" {}
def RenderVar "V" {}
def RenderPass "R" {}
def Camera "C" {}
def Scope "O" {}
def FutureRenderVar "F" {}
def UnknownType "U" {}
def "T" {}
"""


def test_is_a_answers_as_usd_for_every_type_and_after_an_edit() -> None:
    # The render schemas' answers are kept for the process by schema type name
    # (PrimValues.is_a): a fallback type, an unknown type, a typeless prim and
    # an edited type must still answer as prim.IsA does.
    from usdrender_lint.api import schemas

    # Every schema whose answer is kept, and a class, which is asked of USD each time.
    kinds = (*resolve._RENDER_SCHEMAS.values(), UsdRender.SettingsBase)
    assert len(kinds) == 7
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(IS_A_SHOT)
    stage = Usd.Stage.Open(layer)
    for _ in range(2):  # the second lint answers from what the first kept
        with lint_cache():
            for prim in stage.Traverse():
                values = resolve.prim_values(prim)
                assert [values.is_a(k) for k in kinds] == [prim.IsA(k) for k in kinds], prim
    layer.GetPrimAtPath("/O").typeName = "RenderVar"
    layer.GetPrimAtPath("/V").typeName = "Scope"
    with lint_cache():
        assert resolve.prim_values(stage.GetPrimAtPath("/O")).is_a(schemas.RenderVar)
        assert not resolve.prim_values(stage.GetPrimAtPath("/V")).is_a(schemas.RenderVar)
    assert resolve.prim_values(stage.GetPrimAtPath("/F")).is_a(schemas.RenderVar)  # no lint


def test_a_second_lint_sees_edited_relationship_targets(stage) -> None:
    linter = Linter(all_rules(), raise_errors=True)
    camera = _settings(stage).CreateRelationship("camera")
    camera.SetTargets([Sdf.Path("/Missing")])
    assert "CA003" in {f.code for f in linter.lint_stage(stage)}
    stage.DefinePrim("/Cam", "Camera")
    camera.SetTargets([Sdf.Path("/Cam")])
    assert "CA003" not in {f.code for f in linter.lint_stage(stage)}


def test_each_caller_gets_a_target_list_of_its_own(stage) -> None:
    rel = _settings(stage).CreateRelationship("camera")
    rel.SetTargets([Sdf.Path("/Cam")])
    with lint_cache():
        resolve.forwarded_targets(rel).append(Sdf.Path("/Other"))
        assert resolve.forwarded_targets(rel) == [Sdf.Path("/Cam")]
        assert resolve.authored_targets(rel) == [Sdf.Path("/Cam")]


def test_the_declared_type_shortcut_keeps_schema_and_custom_answers(stage) -> None:
    # USD takes a schema attribute's type from the prim definition: a spec of that
    # type is never mismatched, so resolve.py skips the schema lookup for it.
    resolution = _settings(stage).GetAttribute("resolution")
    assert resolution.GetTypeName() == Sdf.ValueTypeNames.Int2  # the spec says float2
    assert resolve.mismatched_spec(resolution) is not None
    assert len(resolve.mismatched_specs(resolution)) == 1
    with lint_cache():
        values = resolve.prim_values(_settings(stage))
        assert len(values.mismatched_specs("resolution")) == 1
        assert values.mismatched_specs("aspectRatioConformPolicy") == []  # well-typed

    weak = Sdf.Layer.CreateAnonymous(".usda")
    weak.ImportFromString('#usda 1.0\nover "S"\n{\n    custom int2 extra = (1, 2)\n}\n')
    strong = Sdf.Layer.CreateAnonymous(".usda")
    strong.ImportFromString(
        f"#usda 1.0\n(\n    subLayers = [@{weak.identifier}@]\n)\n"
        'def RenderSettings "S"\n{\n    custom float2 extra\n}\n'
    )
    custom = Usd.Stage.Open(strong)
    extra = custom.GetAttributeAtPath("/S.extra")
    for memo in (lint_cache(), contextlib.nullcontext()):
        with memo:
            assert extra.GetTypeName() == Sdf.ValueTypeNames.Float2  # the strongest spec's
            assert resolve.mismatched_spec(extra) is None  # no schema type to differ from
            assert resolve.mismatched_specs(extra) == []
            assert resolve.has_authored_value(extra)


#: (prim type, attribute, the weak sublayer's opinion, the strong layer's):
#: PrimValues reads an authored default of the strongest spec as the value,
#: without HasAuthoredValue or Get; a block, an array, an asset, a time code or
#: a path expression must still give USD's answers.
_RES = "uniform int2 resolution"
_PAR = "uniform float pixelAspectRatio"
_PURPOSES = "uniform token[] includedPurposes"
_EXPRESSION = "uniform pathExpression collection:renderVisibility:membershipExpression"
_OPINIONS = [
    ("RenderSettings", "resolution", "", f"{_RES} = (2, 3)"),
    ("RenderSettings", "resolution", f"{_RES} = (2, 3)", f"{_RES} = None"),
    ("RenderSettings", "resolution", f"{_RES} = (2, 3)", f"{_RES} = AnimationBlock"),
    ("RenderSettings", "resolution", f"{_RES}.timeSamples = {{1: (2, 3)}}", f"{_RES} = None"),
    ("RenderSettings", "resolution", "", f"{_RES}.timeSamples = {{1: None}}"),
    ("RenderSettings", "resolution", f"{_RES} = (2, 3)", f"{_RES}.timeSamples = {{}}"),
    ("RenderSettings", "resolution", "", f"{_RES} = (5, 5)\n{_RES}.timeSamples = {{1: (7, 7)}}"),
    ("RenderSettings", "resolution", f"{_RES} = (2, 3)", "uniform float2 resolution = (4, 5)"),
    ("RenderSettings", "pixelAspectRatio", "", f"{_PAR} = 3\n{_PAR}.spline = {{1: 1, 10: 2}}"),
    ("RenderSettings", "aspectRatioConformPolicy", "", "token aspectRatioConformPolicy = </X>"),
    ("RenderSettings", "includedPurposes", f'{_PURPOSES} = ["render"]', f"{_PURPOSES} = []"),
    ("RenderSettings", "extra", "", "custom int extra = 4"),
    ("RenderPass", "fileName", "", "uniform asset fileName = @{weak}@"),  # Get resolves it
    ("RenderPass", _EXPRESSION.split()[-1], "", f'{_EXPRESSION} = "/P/geo"'),  # mapped to /Q
    ("SpatialAudio", "startTime", "uniform timecode startTime = 10", ""),  # offset by 5
]


@pytest.mark.parametrize(("prim_type", "name", "weak", "strong"), _OPINIONS)
def test_the_strongest_default_answers_as_usd_does(prim_type, name, weak, strong) -> None:
    weak_layer = Sdf.Layer.CreateAnonymous(".usda")
    weak_layer.ImportFromString(f'#usda 1.0\nover "P"\n{{\n    {weak}\n}}\n')
    strong = strong.replace("{weak}", weak_layer.identifier)
    strong_layer = Sdf.Layer.CreateAnonymous(".usda")
    strong_layer.ImportFromString(
        f"#usda 1.0\n(\n    subLayers = [@{weak_layer.identifier}@ (offset = 5)]\n)\n"
        f'def {prim_type} "P"\n{{\n    {strong}\n}}\n'
        f'def {prim_type} "Q" (references = </P>)\n{{\n}}\n'
    )
    stage = Usd.Stage.Open(strong_layer)
    for path in ("/P", "/Q"):
        prim = stage.GetPrimAtPath(path)
        attr = prim.GetAttribute(name)
        expected = resolve.has_authored_value(attr)  # HasAuthoredValue and the specs
        # Without time samples or a spline in any layer (the engine knows from their
        # words) no spec is asked for them, with the same answers.
        varying = any(w in weak + strong for w in (".timeSamples", ".spline"))
        for without_clips, without_varying in ((True, not varying), (True, False), (False, False)):
            values = resolve.PrimValues(prim, without_clips, without_varying)
            assert values.has_value(name) == expected
            assert values.authored(name) == (attr.Get() if expected else None)
            # "may": False only where USD finds no time samples at all.
            assert values.may_vary(name) or attr.GetNumTimeSamples() == 0
            values = resolve.PrimValues(prim, without_clips, without_varying)
            assert values.authored(name) == (attr.Get() if expected else None)  # unasked


@pytest.mark.parametrize(("prim_type", "name", "weak", "strong"), _OPINIONS)
def test_a_prim_with_one_spec_answers_without_a_property_stack(
    prim_type, name, weak, strong, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A prim that one spec defines reads its attributes from that spec's
    # properties: the answers are USD's, and no property stack is asked.
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(
        f'#usda 1.0\ndef {prim_type} "P"\n{{\n    {strong.replace("{weak}", "x.usda")}\n}}\n'
    )
    stage = Usd.Stage.Open(layer)
    prim = stage.GetPrimAtPath("/P")
    attr = prim.GetAttribute(name)
    expected = resolve.has_authored_value(attr)  # read outside a lint: by its property stack
    mismatched = resolve.mismatched_specs(attr)
    stacks: list[Usd.Property] = []
    stack = resolve._property_stack
    monkeypatch.setattr(resolve, "_property_stack", lambda a, t: stacks.append(a) or stack(a, t))
    varying = any(w in strong for w in (".timeSamples", ".spline"))
    for without_clips, without_varying in ((True, not varying), (False, False)):
        values = resolve.PrimValues(prim, without_clips, without_varying)
        assert values.has_value(name) == expected
        assert values.authored(name) == (attr.Get() if expected else None)
        assert values.mismatched_specs(name) == mismatched
    if values.schema_attribute(name).value_type is not None:  # a custom one's type is its stack's
        assert stacks == []


def test_an_expired_or_null_prim_raises_instead_of_reaching_usd_unbound() -> None:
    # resolve calls USD's methods unbound (skipping Usd.Object's validity
    # check): on an expired prim that call would crash the process, so the
    # entry points check validity first and raise as a bound call would.
    stage = Usd.Stage.CreateInMemory()
    stage.GetRootLayer().ImportFromString(SHOT)
    expired = stage.GetPrimAtPath("/Render/Settings")
    stage.RemovePrim("/Render/Settings")
    for prim in (expired, Usd.Prim()):
        assert not resolve.is_usable(prim)
        with pytest.raises(RuntimeError, match="not a valid prim"):
            resolve.unusable_reason(prim)
        with pytest.raises(RuntimeError, match="not a valid prim"):
            resolve.PrimValues(prim)


def test_handles_of_one_prim_share_its_values_and_its_path_is_asked_once() -> None:
    stage = Usd.Stage.CreateInMemory()
    stage.GetRootLayer().ImportFromString(SHOT)
    cache = LintCache()
    first = stage.GetPrimAtPath("/Render/Settings")
    again = stage.GetPrimAtPath("/Render/Settings")  # another handle, equal
    other = stage.GetPrimAtPath("/Render")
    values = resolve.values_in(cache, first)
    assert resolve.values_in(cache, again) is values
    assert resolve.values_in(cache, first) is values
    assert resolve.values_in(cache, other) is not values
    assert values.path == first.GetPath()
    assert values.path is values.path  # asked of USD once: each GetPath() is a new object


def test_a_stage_without_time_samples_or_splines_asks_no_spec_for_them(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    asked: list[str] = []
    has_info = Sdf.Spec.HasInfo

    def counting(spec: Sdf.Spec, key: str) -> bool:
        asked.append(key)
        return has_info(spec, key)

    monkeypatch.setattr(Sdf.Spec, "HasInfo", counting)
    still = tmp_path / "still.usda"
    still.write_text(SHOT)
    findings = Linter(all_rules()).lint_path(str(still)).findings
    assert not {"timeSamples", "spline"} & set(asked)
    moving = tmp_path / "moving.usda"
    moving.write_text(SHOT.replace("{", "{\n    float unrelated.timeSamples = {1: 2}", 1))
    Linter(all_rules()).lint_path(str(moving))
    assert "timeSamples" in asked  # a layer that may hold them: every spec is asked
    assert findings == Linter(all_rules()).lint_path(str(still)).findings
