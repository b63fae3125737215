"""PA003 input-passes-cycle."""

from __future__ import annotations

from collections.abc import Iterator

from usdrender_lint.api import Context, Diagnostic, Rule, Severity

from .._passes import find_cycles, input_pass_graph


class InputPassesCycle(Rule):
    """RenderPasses depend on each other in a cycle through inputPasses.

    ## What it does
    Builds the graph pass -> each valid forwarded `inputPasses` target (PA002
    reports the invalid ones) and reports each cycle a depth-first search
    closes, a pass that lists itself included, once, with the cycle's passes
    in the message. The finding is on the `inputPasses` of the cycle's pass
    with the smallest path.

    ## Why is this bad?
    *"The consumer of this RenderPass graph of inputs will need to resolve the
    transitive dependencies."* (`pxr/usd/usdRender/schema.usda`, RenderPass
    `inputPasses`). A cycle cannot be resolved: the task graph is
    unschedulable (a deadlock or a submission failure).

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderPass "shadows"
        {
            uniform token passType = "prman"
            rel inputPasses = </Render/comp>
        }

        def RenderPass "lighting"
        {
            uniform token passType = "prman"
            rel inputPasses = </Render/shadows>
        }

        def RenderPass "comp"
        {
            uniform token passType = "nuke"
            rel inputPasses = </Render/lighting>
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderPass "shadows"
        {
            uniform token passType = "prman"
        }

        def RenderPass "lighting"
        {
            uniform token passType = "prman"
            rel inputPasses = </Render/shadows>
        }

        def RenderPass "comp"
        {
            uniform token passType = "nuke"
            rel inputPasses = </Render/lighting>
        }
    }
    ```

    ## Fix safety
    No automatic fix: which dependency is wrong is the author's call.
    """

    code = "PA003"
    name = "input-passes-cycle"
    severity = Severity.ERROR
    partial_composition = True

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for cycle in find_cycles(input_pass_graph(ctx)):
            first = ctx.stage.GetPrimAtPath(cycle[0])
            chain = " -> ".join(f"<{p}>" for p in (*cycle, cycle[0]))
            what = (
                "lists itself in inputPasses"
                if len(cycle) == 1
                else "is part of an inputPasses cycle"
            )
            yield Diagnostic(
                message=f"RenderPass {cycle[0]} {what}: {chain}; the pass graph cannot be "
                "scheduled; remove one of these dependencies",
                at=first.GetRelationship("inputPasses"),
            )
