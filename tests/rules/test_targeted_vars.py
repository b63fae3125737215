"""VA008 and PR006 ask their question of the few vars products target, once per
lint: a repeat across products is no finding, one within a product still is,
and a Context made by hand (no walk) still checks each product."""

from __future__ import annotations

from rule_support import diagnostics, stage_from_text

from usdrender_lint.api import Context
from usdrender_lint.rules.products.pr006_duplicate_render_vars import DuplicateRenderVars
from usdrender_lint.rules.vars.va008_aov_name_collision import AovNameCollision

# Two vars named "diffuse" with the same source, in different scopes: Beauty
# and Lighting each output one of them, Both outputs both.
STAGE = """#usda 1.0
def Scope "Render"
{
    def RenderProduct "Beauty"
    {
        rel orderedVars = [</Render/A/diffuse>]
    }
    def RenderProduct "Lighting"
    {
        rel orderedVars = [</Render/B/diffuse>]
    }
    def RenderProduct "Both"
    {
        rel orderedVars = [</Render/A/diffuse>, </Render/B/diffuse>]
    }
    def Scope "A"
    {
        def RenderVar "diffuse"
        {
            string sourceName = "albedo"
        }
    }
    def Scope "B"
    {
        def RenderVar "diffuse"
        {
            string sourceName = "albedo"
        }
    }
}
"""


def _without(product: str) -> str:
    """STAGE without the product named ``product``."""
    start = STAGE.index(f'    def RenderProduct "{product}"')
    end = STAGE.index("    }\n", start) + len("    }\n")
    return STAGE[:start] + STAGE[end:]


def test_a_repeat_across_products_is_no_finding() -> None:
    stage = stage_from_text(_without("Both"))
    assert diagnostics(AovNameCollision(), stage) == []
    assert diagnostics(DuplicateRenderVars(), stage) == []


def test_a_repeat_within_a_product_is_reported_once_on_it() -> None:
    stage = stage_from_text(STAGE)
    for rule in (AovNameCollision(), DuplicateRenderVars()):
        (found,) = diagnostics(rule, stage)
        assert "of /Render/Both" in found.message


def test_a_context_made_by_hand_still_checks_the_product() -> None:
    stage = stage_from_text(STAGE)
    both = stage.GetPrimAtPath("/Render/Both")
    for rule in (AovNameCollision(), DuplicateRenderVars()):
        (found,) = rule.check_prim(both, Context(stage, "memory.usda"))
        assert "of /Render/Both" in found.message
