"""SE009 included-purposes-invalid."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd, Vt

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, schemas
from usdrender_lint.api.resolve import items, prim_values

from .._corrections import set_value
from ._messages import _fmt, _quoted
from ._purposes import _duplicates

#: The purposes UsdGeom knows, in its order.
_PURPOSES = schemas.ORDERED_PURPOSES
#: Entries of a long list that are checked (a list past four entries is wrong anyway).
CHECKED_ENTRIES = 10_000


class IncludedPurposesInvalid(Rule):
    """includedPurposes names a purpose that does not exist, or repeats one.

    ## What it does
    Checks an authored `includedPurposes` on a RenderSettings: every token must
    be an imageable purpose (`UsdGeom.Imageable.GetOrderedPurposeTokens()`:
    `default`, `render`, `proxy`, `guide` in usd-core 26.11), listed once.

    ## Why is this bad?
    *"Imageable purpose values (e.g. default, render, proxy, guide) that should
    be included in the render."* (RenderSettings prim definition, usd-core
    26.11); *"A prim can only have one purpose, and the purpose can be one of
    the following: default … render … proxy … guide"*
    (`docs/user_guides/render_user_guide.rst`). A token such as `preview` (a
    material-binding purpose) matches no prim.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform token[] includedPurposes = ["default", "render", "preview"]
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
            uniform token[] includedPurposes = ["default", "render"]
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when the only problem is repeated tokens, the fix drops
    the repeats and keeps the order. Unknown tokens are not fixed, nor is a
    list of more than 10,000 entries (only its first 10,000 are checked: any
    list of more than four entries repeats or misnames a purpose).
    """

    code = "SE009"
    name = "included-purposes-invalid"
    severity = Severity.WARNING
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = (schemas.RenderSettings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        purposes = values.authored("includedPurposes")
        if purposes is None:
            return
        attr = values.attribute("includedPurposes")
        # Any list of more than four entries repeats or misnames one, so a long
        # list is judged by its start; it gets no fix (that would need it all).
        whole = len(purposes) <= CHECKED_ENTRIES
        tokens = items(purposes if whole else purposes[:CHECKED_ENTRIES])
        known = _PURPOSES
        unknown = [t for t in dict.fromkeys(tokens) if t not in known]
        repeated = _duplicates(tokens)
        problems = []
        if unknown:
            verb = "is not a purpose" if len(unknown) == 1 else "are not purposes"
            problems.append(f"{_quoted(unknown)} {verb}")
        if repeated:
            problems.append(
                f"{_quoted(repeated)} {'is' if len(repeated) == 1 else 'are'} listed more than once"
            )
        if not problems:
            return
        if not whole:
            problems.append(f"the first {CHECKED_ENTRIES:,} of {len(purposes):,} entries checked")
        fix = None
        if not unknown and whole:
            unique = Vt.TokenArray(list(dict.fromkeys(tokens)))
            fix = Fix(
                description="drop the repeated purposes",
                safe=True,
                apply=set_value(attr.GetPath(), unique),
            )
        yield Diagnostic(
            message=f"includedPurposes {_fmt(purposes)}: {'; '.join(problems)}; list each of "
            f"{', '.join(known)} at most once",
            at=attr,
            fix=fix,
        )
