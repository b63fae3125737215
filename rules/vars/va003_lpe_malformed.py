"""VA003 lpe-malformed."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator

from pxr import Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, record, schemas

from .._aov import checked_value
from .._corrections import set_value
from .._lpe import Dialect, lpe_problem, strip_renderer_prefix


class LpeMalformed(Rule):
    """A RenderVar's light path expression does not parse.

    ## What it does
    For a RenderVar whose composed `sourceType` is `lpe`, parses `sourceName`
    with the OSL light-path-expression grammar (`src/liboslexec/lpeparse.cpp`)
    after stripping one leading renderer prefix `lpe:` (itself reported as
    non-portable). It reports unbalanced `( )`, `[ ]`, `< >` or quotes, `|`
    without an operand, `<...>` nested in `<...>`, repetition inside `<...>`,
    a malformed `{n,m}`, an empty `[^]`, unknown labels, a label in the wrong
    position of `<...>` (event type first, scattering type second), and an
    expression that cannot begin with the camera event `C`.

    ## Why is this bad?
    *"lpe": Specifies a Light Path Expression in the OSL Light Path
    Expressions language as the source for this RenderVar. Some renderers may
    use extensions to that syntax, which will necessarily be non-portable.*
    (`pxr/usd/usdRender/schema.usda`). A malformed LPE is only discovered when
    the renderer starts, as an error or silently as a black channel, after the
    job has queued on the farm. One of hdPrman's code paths prepends `lpe:`
    itself, so a prefixed source becomes `lpe:lpe:...`.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "directDiffuse"
            {
                string sourceName = "C<RD>[<L.>O"
                uniform token sourceType = "lpe"
            }
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "directDiffuse"
            {
                string sourceName = "C<RD>[<L.>O]"
                uniform token sourceType = "lpe"
            }
        }
    }
    ```

    ## Fix safety
    Safe, conditional: only a leading `lpe:` prefix is fixed (removed).
    Syntax errors have no automatic fix.

    ## Options
    `dialect` (`"osl"`, default, or `"extended"`): `extended` admits renderer
    extensions, the `?` modifier and labels OSL does not define.
    `extra-labels` (list of one-character strings): labels to admit in the
    `osl` dialect, e.g. `["U"]`.
    """

    code = "VA003"
    name = "lpe-malformed"
    severity = Severity.ERROR
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = (schemas.RenderVar,)

    @record(frozen=True)
    class Options:
        dialect: Dialect = "osl"
        extra_labels: tuple[str, ...] = ()

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        if checked_value(prim, "sourceType", ctx) != "lpe":
            return
        source = checked_value(prim, "sourceName", ctx)
        if not source:
            return
        attr = prim.GetAttribute("sourceName")
        expression, prefixed = strip_renderer_prefix(source)
        problem = lpe_problem(expression, self.options.dialect, self.options.extra_labels)
        parts, advice = [], []
        if prefixed:
            parts.append(
                "starts with the non-portable renderer prefix 'lpe:' (hdPrman adds it itself, "
                "giving 'lpe:lpe:...')"
            )
            advice.append("remove the prefix")
        if problem is not None:
            shift = len(source) - len(expression)
            problem = dataclasses.replace(problem, position=problem.position + shift)
            parts.append(f"is malformed: {problem}")
            advice.append("correct the expression (OSL syntax, e.g. C<RD>[<L.>O])")
        if not parts:
            return
        fix = None
        if prefixed:
            fix = Fix(
                description="remove the leading 'lpe:'",
                safe=True,
                apply=set_value(attr.GetPath(), expression),
            )
        yield Diagnostic(
            message=f"light path expression {source!r} of RenderVar {prim.GetPath()} "
            f"{' and '.join(parts)}; {' and '.join(advice)}",
            at=attr,
            fix=fix,
        )
