"""PA007 pass-type-empty."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values

from ._default_value import _value_lost_elsewhere


class PassTypeEmpty(Rule):
    """A RenderPass has no passType.

    ## What it does
    Reports a RenderPass whose `passType` (a token with no fallback) is
    unauthored, blocked or the empty token. A `passType` authored with the
    wrong type (SE016) or only as time samples (SE017) is left to those rules.

    ## Why is this bad?
    *"A string used to categorize differently structured or executed types of
    passes within a customized pipeline."* (`pxr/usd/usdRender/schema.usda`,
    RenderPass `passType`). Job-submission code dispatches on it; a pass
    without a type is usually routed to a default handler.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
        }

        def RenderPass "beauty"
        {
            rel renderSource = </Render/Settings>
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
        }

        def RenderPass "beauty"
        {
            uniform token passType = "prman"
            rel renderSource = </Render/Settings>
        }
    }
    ```

    ## Fix safety
    No automatic fix: the pass type is a pipeline choice.
    """

    code = "PA007"
    name = "pass-type-empty"
    severity = Severity.INFO
    partial_composition = True
    prim_types = (schemas.RenderPass,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        if _value_lost_elsewhere(values, "passType"):
            return
        if values.authored("passType"):
            return
        state = "is the empty token" if values.has_value("passType") else "is not set"
        yield Diagnostic(
            message=f"passType of RenderPass {prim.GetPath()} {state}; author the pipeline's pass "
            'type (e.g. "prman", "nuke") so job submission can dispatch the pass',
            at=values.attribute("passType") if values.has_value("passType") else prim,
        )
