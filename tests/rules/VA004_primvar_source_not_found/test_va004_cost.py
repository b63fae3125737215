"""VA004 walks the scene only when a primvar-sourced RenderVar exists, once per
stage, and never on a stage the user masked."""

from __future__ import annotations

from pathlib import Path

from pxr import Usd

from usdrender_lint.engine import Linter
from usdrender_lint.rules.vars import va004_primvar_source_not_found as vars
from usdrender_lint.rules.vars.va004_primvar_source_not_found import PrimvarSourceNotFound

FOLDER = Path(__file__).parent
TWO_PRIMVAR_VARS = """#usda 1.0

def Xform "World"
{
    def Mesh "card"
    {
        float[] primvars:wetness = [1]
    }
}

def Scope "Render"
{
    def Scope "Vars"
    {
        def RenderVar "uv"
        {
            string sourceName = "uv"
            uniform token sourceType = "primvar"
        }

        def RenderVar "wet"
        {
            string sourceName = "wetness"
            uniform token sourceType = "primvar"
        }

        def RenderVar "color"
        {
            string sourceName = "Ci"
        }
    }
}
"""


def _count_walks(monkeypatch) -> list[int]:
    calls: list[int] = []
    real = vars._scene_primvar_names

    def counting(stage: Usd.Stage):
        calls.append(1)
        return real(stage)

    monkeypatch.setattr(vars, "_scene_primvar_names", counting)
    return calls


def test_no_scene_walk_without_primvar_vars(monkeypatch) -> None:
    calls = _count_walks(monkeypatch)
    linter = Linter([PrimvarSourceNotFound()], raise_errors=True)
    result = linter.lint_path(str(FOLDER.parent / "VA001_source_name_empty" / "fail_empty.usda"))
    assert result.findings == ()
    assert calls == []


def test_one_scene_walk_per_stage(monkeypatch, tmp_path: Path) -> None:
    calls = _count_walks(monkeypatch)
    path = tmp_path / "two.usda"
    path.write_text(TWO_PRIMVAR_VARS, encoding="utf-8")
    result = Linter([PrimvarSourceNotFound()], raise_errors=True).lint_path(str(path))
    assert [f.location.path for f in result.findings] == ["/Render/Vars/uv.sourceName"]
    assert calls == [1]


def test_skipped_on_a_user_masked_stage(tmp_path: Path) -> None:
    path = tmp_path / "two.usda"
    path.write_text(TWO_PRIMVAR_VARS, encoding="utf-8")
    mask = Usd.StagePopulationMask(["/Render"])
    stage = Usd.Stage.OpenMasked(str(path), mask)
    linter = Linter([PrimvarSourceNotFound()], raise_errors=True)
    assert linter.lint_stage(stage, str(path)) == []
