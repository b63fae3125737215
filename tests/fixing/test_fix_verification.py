"""Every fix is verified: a fix whose finding remains after it is undone and
reported as not applied, with the reason; the other fixes still apply."""

from __future__ import annotations

from pathlib import Path

from pxr import Sdf, UsdRender

from usdrender_lint.api import Diagnostic, Fix, Rule, Severity
from usdrender_lint.engine import Linter
from usdrender_lint.fixing import FixOptions, fix_files

WEAK = """#usda 1.0

over "Render"
{
    over "Strong"
    {
    }
}
"""
SHOT = """#usda 1.0
(
    subLayers = [@weak.usda@]
)

def Scope "Render"
{
    def RenderSettings "Strong"  # the strong opinion
    {
        custom string note = "bad"
    }

    def RenderSettings "Plain"
    {
        custom string note = "bad"
    }
}
"""


class NoteIsBad(Rule):
    """A rule for the test: a note must not be "bad". Its fix writes into the
    weaker sublayer when the prim is named Strong, which the root layer's
    stronger opinion then hides: composition undoes that fix.

    ## Fix safety
    Safe.
    """

    code = "TV001"
    name = "note-is-bad"
    severity = Severity.ERROR
    prim_types = (UsdRender.Settings,)
    fix_safety = "safe"

    def check_prim(self, prim, ctx):
        attr = prim.GetAttribute("note")
        if attr.Get() == "bad":
            folder = Path(prim.GetStage().GetRootLayer().realPath).parent
            weak = Sdf.Layer.Find(str(folder / "weak.usda"))
            target = weak if prim.GetName() == "Strong" else None
            path = attr.GetPath()

            def apply(stage):
                stage.GetAttributeAtPath(path).Set("good")

            yield Diagnostic(
                message=f"{prim.GetName()}: the note is bad",
                at=attr,
                fix=Fix(description="make it good", safe=True, apply=apply, layer=target),
            )


def run(tmp_path: Path):
    (tmp_path / "weak.usda").write_text(WEAK, encoding="utf-8")
    shot = tmp_path / "shot.usda"
    shot.write_text(SHOT, encoding="utf-8")
    result = fix_files(Linter([NoteIsBad()]), [str(shot)], FixOptions())
    return shot, result


def test_a_fix_that_composition_undoes_is_undone_and_reported(tmp_path: Path) -> None:
    shot, result = run(tmp_path)
    by_path = {o.path: o for o in result.outcomes}
    strong = by_path["/Render/Strong.note"]
    assert not strong.applied
    assert "its finding remains after the fix" in strong.reason
    # The weaker layer it wrote to is as it was; the other fix is applied.
    assert (tmp_path / "weak.usda").read_text(encoding="utf-8") == WEAK
    assert by_path["/Render/Plain.note"].applied
    text = shot.read_text(encoding="utf-8")
    assert text == SHOT.replace(
        'custom string note = "bad"\n    }\n}', 'custom string note = "good"\n    }\n}'
    )


def test_a_second_run_changes_nothing(tmp_path: Path) -> None:
    shot, _ = run(tmp_path)
    fixed = shot.read_bytes(), (tmp_path / "weak.usda").read_bytes()
    again = fix_files(Linter([NoteIsBad()]), [str(shot)], FixOptions())
    assert (shot.read_bytes(), (tmp_path / "weak.usda").read_bytes()) == fixed
    assert not again.applied
    assert [o.path for o in again.unapplied] == ["/Render/Strong.note"]


class FixDoesNothingUseful(Rule):
    """A rule for the test whose fix edits the prim without silencing it.

    ## Fix safety
    Safe.
    """

    code = "TV002"
    name = "fix-does-nothing-useful"
    severity = Severity.ERROR
    prim_types = (UsdRender.Settings,)
    fix_safety = "safe"

    def check_prim(self, prim, ctx):
        path = prim.GetPath()

        def apply(stage):
            stage.GetPrimAtPath(path).SetCustomDataByKey("tried", True)

        yield Diagnostic(
            message="always", at=prim, fix=Fix(description="try", safe=True, apply=apply)
        )


def test_an_undone_fix_leaves_a_usdc_byte_for_byte(tmp_path: Path) -> None:
    source = Sdf.Layer.CreateAnonymous(".usda")
    source.ImportFromString(SHOT.replace("    subLayers = [@weak.usda@]\n", ""))
    crate = tmp_path / "shot.usdc"
    source.Export(str(crate))
    before = crate.read_bytes(), crate.stat().st_ino
    result = fix_files(Linter([FixDoesNothingUseful()]), [str(crate)], FixOptions())
    assert result.outcomes and not result.applied
    assert (crate.read_bytes(), crate.stat().st_ino) == before  # not even written again
