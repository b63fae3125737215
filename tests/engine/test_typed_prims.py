"""engine/typed_prims.py finds exactly the prims, in exactly the order, that a
Python walk of ``stage.Traverse()`` keeps, or says it cannot."""

from __future__ import annotations

from pathlib import Path

import pytest
from pxr import Sdf, Tf, Usd

from usdrender_lint.engine import Linter, typed_prims
from usdrender_lint.testing import all_rules

TESTS = Path(__file__).parents[1]
FIXTURES = sorted((TESTS / "rules").glob("*/*.usda"))


@pytest.fixture(autouse=True)
def _every_size(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(typed_prims, "MIN_PRIMS", 0)
    monkeypatch.setattr(typed_prims, "MIN_SPECS", 0)


def _walked(stage: Usd.Stage, linter: Linter) -> list[Sdf.Path]:
    return [p.GetPath() for p in stage.Traverse() if linter._dispatch.wants(p.GetTypeName())]


def _found(stage: Usd.Stage, linter: Linter) -> list[Sdf.Path] | None:
    dispatch = linter._dispatch
    found = typed_prims.find(stage, dispatch.wants, dispatch.unknown_type_names)
    assert not stage.GetSessionLayer().rootPrims, "the query prim is removed"
    return None if found is None else [p.GetPath() for p in found]


def _open(path: Path) -> Usd.Stage | None:
    try:
        return Usd.Stage.Open(str(path), Usd.Stage.LoadAll)
    except Tf.ErrorException:
        return None


def test_every_fixture_gives_the_walk_s_prims_in_the_walk_s_order() -> None:
    linter = Linter(all_rules())
    compared = 0
    for path in FIXTURES:
        stage = _open(path)
        if stage is None:
            continue
        found = _found(stage, linter)
        if found is not None:
            assert found == _walked(stage, linter), path
            compared += 1
    assert compared > 300


def test_the_shared_corpus_gives_the_walk_s_prims(shared_dir: Path) -> None:
    linter = Linter(all_rules())
    for path in sorted((shared_dir / "corpus").rglob("*.usd*")):
        stage = _open(path)
        if stage is not None:
            found = _found(stage, linter)
            assert found is None or found == _walked(stage, linter), path


def test_instances_inactive_prims_overs_and_order(tmp_path: Path) -> None:
    layer = tmp_path / "shot.usda"
    layer.write_text(
        """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Z"
    {
    }
    def RenderSettings "A"
    {
    }
    def Scope "Inner"
    {
        def RenderVar "v"
        {
        }
    }
    over "Over"
    {
        def RenderProduct "p"
        {
        }
    }
    def Scope "Off" (
        active = false
    )
    {
        def RenderProduct "q"
        {
        }
    }
}
class "Proto"
{
    def RenderSettings "InClass"
    {
    }
}
def Xform "Inst" (
    instanceable = true
    references = </Proto>
)
{
}
def RenderPass "Last"
{
}
"""
    )
    stage = Usd.Stage.Open(str(layer))
    linter = Linter(all_rules())
    assert (
        _found(stage, linter)
        == [Sdf.Path(p) for p in ("/Render/Z", "/Render/A", "/Render/Inner/v", "/Last")]
        == _walked(stage, linter)
    )


def test_an_unknown_type_or_a_busy_session_layer_sends_the_caller_to_its_walk(
    tmp_path: Path,
) -> None:
    linter = Linter(all_rules())
    unknown = tmp_path / "unknown.usda"
    unknown.write_text('#usda 1.0\ndef RenderSetings "typo"\n{\n}\n')
    assert _found(Usd.Stage.Open(str(unknown)), linter) is None
    named_untyped = tmp_path / "untyped.usda"
    named_untyped.write_text('#usda 1.0\ndef untyped "odd"\n{\n}\n')
    assert _found(Usd.Stage.Open(str(named_untyped)), linter) is None
    stage = Usd.Stage.Open(str(TESTS / "rules" / "SE003_data_window_malformed" / "pass_traps.usda"))
    over = Sdf.CreatePrimInLayer(stage.GetSessionLayer(), "/Render")
    over.specifier = Sdf.SpecifierOver
    over.SetInfo("active", False)
    dispatch = linter._dispatch
    assert typed_prims.find(stage, dispatch.wants, dispatch.unknown_type_names) is None


def test_variant_selections_in_the_session_layer_keep_the_lookup() -> None:
    """--variants authors its selections in the session layer: the query is
    authored beside them and they stay."""
    stage = Usd.Stage.Open(str(FIXTURES[0]))
    session = stage.GetSessionLayer()
    Sdf.CreatePrimInLayer(session, "/Render").variantSelections["look"] = "b"
    dispatch = Linter(all_rules())._dispatch
    found = typed_prims.find(stage, dispatch.wants, dispatch.unknown_type_names)
    assert found is not None
    assert [p.GetPath() for p in found] == [
        p.GetPath() for p in stage.Traverse() if dispatch.wants(p.GetTypeName())
    ]
    assert [p.path for p in session.rootPrims] == [Sdf.Path("/Render")]
    assert session.GetPrimAtPath("/Render").variantSelections["look"] == "b"


@pytest.mark.parametrize("limit", ["MIN_PRIMS", "MIN_SPECS"])
def test_small_stages_are_walked(monkeypatch: pytest.MonkeyPatch, limit: str) -> None:
    monkeypatch.setattr(typed_prims, limit, 10**9)
    stage = Usd.Stage.Open(str(FIXTURES[0]))
    dispatch = Linter(all_rules())._dispatch
    assert typed_prims.find(stage, dispatch.wants, dispatch.unknown_type_names) is None


def test_the_engine_reports_the_same_with_either_walk(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    linter = Linter(all_rules())
    for path in FIXTURES[::7]:
        queried = linter.lint_path(str(path))
        monkeypatch.setattr(typed_prims, "MIN_PRIMS", 10**9)
        walked = linter.lint_path(str(path))
        monkeypatch.setattr(typed_prims, "MIN_PRIMS", 0)
        assert queried == walked, path
