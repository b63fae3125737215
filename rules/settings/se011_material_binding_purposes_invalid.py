"""SE011 material-binding-purposes-invalid."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Usd, Vt

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, schemas
from usdrender_lint.api.resolve import items, prim_values

from .._corrections import set_value
from ._messages import _fmt, _quoted
from ._purposes import _duplicates

#: Names people use for the all-purpose binding, whose token is the empty string.
_ALL_PURPOSE_ALIASES = ("allPurpose", "all", "default")


def _problems(unknown: list[str], repeated: list[str]) -> list[str]:
    """What is wrong with the purposes: tokens not allowed, tokens repeated."""
    problems = []
    if unknown:
        problems.append(f"{_quoted(unknown)} not allowed")
    if repeated:
        problems.append(f"{_quoted(repeated)} repeated")
    return problems


def _alias_fix(attr: Usd.Attribute, tokens: list[str]) -> Fix:
    """Author the purposes with each all-purpose alias as the empty token, once each."""
    mapped = ["" if t in _ALL_PURPOSE_ALIASES else t for t in tokens]
    fixed = Vt.TokenArray(list(dict.fromkeys(mapped)))
    return Fix(
        description=f"author {_fmt(fixed)}",
        safe=True,
        apply=set_value(attr.GetPath(), fixed),
    )


class MaterialBindingPurposesInvalid(Rule):
    """materialBindingPurposes names an unknown purpose, repeats one, or is empty.

    ## What it does
    Checks an authored `materialBindingPurposes` on a RenderSettings against
    the attribute's `allowedTokens` (`full`, `preview` and the empty token
    `""` in usd-core 26.11); repeated tokens and an authored empty array are
    reported too.

    ## Why is this bad?
    `allowedTokens = ["full", "preview", ""]` and *"The empty string indicates
    the "allPurpose" binding."* (`pxr/usd/usdRender/schema.usda`). `allPurpose`
    is the C++ name of the empty token, not a value; an empty list names no
    purpose, leaving material resolution to each renderer. USD does not
    enforce `allowedTokens` when authoring.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            uniform token[] materialBindingPurposes = ["full", "allPurpose"]
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
            uniform token[] materialBindingPurposes = ["full", ""]
        }
    }
    ```

    ## Fix safety
    Safe, conditional: `allPurpose`, `all` and `default` become `""` and
    repeats are dropped, keeping the order; other unknown tokens and an empty
    array are not fixed.
    """

    code = "SE011"
    name = "material-binding-purposes-invalid"
    severity = Severity.WARNING
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = (schemas.RenderSettings,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        name = "materialBindingPurposes"
        values = prim_values(prim)
        purposes = values.authored(name)
        if purposes is None:
            return
        attr = values.attribute(name)
        allowed = values.schema_attribute(name).allowed_tokens
        if not purposes:
            yield Diagnostic(
                message="materialBindingPurposes is an authored empty array, which names no "
                "binding "
                'purpose; author e.g. ["full", ""] or remove the opinion',
                at=attr,
            )
            return
        tokens = items(purposes)
        unknown = [t for t in dict.fromkeys(tokens) if t not in allowed]
        problems = _problems(unknown, _duplicates(tokens))
        if not problems:
            return
        fix = _alias_fix(attr, tokens) if all(t in _ALL_PURPOSE_ALIASES for t in unknown) else None
        alias_hint = (
            '; the all-purpose binding is the empty token ""'
            if any(t in _ALL_PURPOSE_ALIASES for t in unknown)
            else ""
        )
        yield Diagnostic(
            message=f"materialBindingPurposes {_fmt(purposes)}: {', '.join(problems)}{alias_hint}; "
            f"use each of {_quoted(allowed)} at most once",
            at=attr,
            fix=fix,
        )
