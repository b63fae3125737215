"""PA002 input-passes-invalid-target."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import prim_values, typed_target_problem


class InputPassesInvalidTarget(Rule):
    """An inputPasses target is not a usable RenderPass.

    ## What it does
    Reports each forwarded `inputPasses` target of a RenderPass that is not a
    prim path, has no prim, is inactive, `over`-only or abstract, or is not a
    RenderPass.

    ## Why is this bad?
    *"The set of other Passes that this Pass depends on in order to be
    constructed properly."* (`pxr/usd/usdRender/schema.usda`, RenderPass
    `inputPasses`). Job-submission code builds the task graph from these
    targets; a target that is not a pass becomes a missing dependency.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
        }

        def RenderPass "composite"
        {
            uniform token passType = "nuke"
            rel renderSource = </Render/Settings>
            rel inputPasses = </Render/Settings>
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

        def RenderPass "composite"
        {
            uniform token passType = "nuke"
            rel renderSource = </Render/Settings>
            rel inputPasses = </Render/beauty>
        }
    }
    ```

    ## Fix safety
    No automatic fix: only the author knows which pass was meant.
    """

    code = "PA002"
    name = "input-passes-invalid-target"
    severity = Severity.ERROR
    partial_composition = True
    prim_types = (schemas.RenderPass,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        for target in values.targets("inputPasses"):
            problem = typed_target_problem(target, schemas.RenderPass, "a RenderPass")
            if problem is not None:
                yield Diagnostic(
                    message=f"inputPasses target <{target.path}> {problem}; list only the "
                    "RenderPass "
                    "prims this pass depends on",
                    at=values.relationship("inputPasses"),
                )
