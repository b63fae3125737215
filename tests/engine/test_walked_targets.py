"""A relationship target that names a prim the engine's walk visited resolves to
that prim's own handle (api/resolve.know_usable): the walk visits only usable
prims, so no GetPrimAtPath and no usability checks are needed, and the rules'
values of the target are found by the handle's identity. A target the walk did
not visit is resolved as before."""

from __future__ import annotations

from pathlib import Path

from pxr import Sdf, Usd

from usdrender_lint.api import Context, Rule, Severity, schemas
from usdrender_lint.api.resolve import Target, know_usable, prim_values, resolve_target
from usdrender_lint.engine import Linter

SHOT = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel products = [</Render/Beauty>, </Render/Missing>, </Render/Hidden>]
    }
    def RenderProduct "Beauty"
    {
    }
    over RenderProduct "Hidden"
    {
    }
}
"""


class WalkedTargets(Rule):
    """Test-only rule: keeps the handles it is given and the settings' targets.

    ## What it does
    Reports nothing.
    """

    code = "TX907"
    name = "test-walked-targets"
    severity = Severity.INFO
    prim_types = (schemas.RenderSettings, schemas.RenderProduct)

    def __init__(self) -> None:
        super().__init__()
        self.given: dict[str, Usd.Prim] = {}
        self.targets: list[Target] = []

    def check_prim(self, prim: Usd.Prim, ctx: Context):
        self.given[str(prim.GetPath())] = prim
        if prim.GetTypeName() == "RenderSettings":
            self.targets.extend(prim_values(prim).targets("products"))
        return ()


def test_a_target_the_walk_visited_is_the_handle_the_rules_are_given(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(SHOT)
    rule = WalkedTargets()
    Linter([rule]).lint_path(str(shot))
    beauty, missing, hidden = rule.targets
    assert beauty.problem is None
    assert beauty.prim is rule.given["/Render/Beauty"]
    assert (missing.prim, missing.problem) == (None, "does not exist on the composed stage")
    assert hidden.problem == "is only an 'over' (never defined)"


def test_outside_a_lint_nothing_is_kept() -> None:
    stage = Usd.Stage.CreateInMemory()
    prim = stage.DefinePrim("/Render/Beauty", "RenderProduct")
    know_usable(stage, [prim])
    target = resolve_target(stage, Sdf.Path("/Render/Beauty"))
    assert target.problem is None
    assert target.prim is not prim  # looked up on the stage, as every call outside a lint
