"""PA005 collection-membership-invalid."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Tf, Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import authored_value

from .._passes import (
    authored_pass_collections,
    collection_label,
    missing_expression_references,
    usd_error_text,
)


def _collection_problems(
    collection: Usd.CollectionAPI,
) -> tuple[list[str], Usd.Property | None]:
    """Why a collection's membership cannot be trusted, and the property the
    first problem is about."""
    # Unbound: the collections are of usable passes (no validity check per call).
    expression_attr = Usd.CollectionAPI.GetMembershipExpressionAttr(collection)
    expression = authored_value(expression_attr)
    includes = Usd.CollectionAPI.GetIncludesRel(collection)
    # Evaluation errors (e.g. an unknown predicate) can surface from Validate()
    # as well as from ComputeMembershipQuery(): report them once.
    evaluation_anchor = expression_attr if expression is not None else includes
    problems: list[tuple[str, Usd.Property]] = []

    def evaluation_failed(exc: Tf.ErrorException) -> None:
        text = f"its membership cannot be computed: {usd_error_text(exc)}"
        problems.append((text, evaluation_anchor))

    try:
        valid, why = Usd.CollectionAPI.Validate(collection)
        if not valid:
            anchor = collection.GetExpansionRuleAttr() if "expansionRule" in why else includes
            problems.append((why.strip().rstrip(".") or "Validate() failed", anchor))
    except Tf.ErrorException as exc:
        evaluation_failed(exc)
    if expression is not None and not expression.IsEmpty():
        for path in missing_expression_references(collection, expression):
            text = (
                f"its membershipExpression references the collection <{path}>, which does "
                "not exist (USD substitutes an empty expression)"
            )
            problems.append((text, expression_attr))
    try:
        Usd.CollectionAPI.ComputeMembershipQuery(collection)
    except Tf.ErrorException as exc:
        evaluation_failed(exc)
    reasons = list(dict.fromkeys(text for text, _ in problems))
    return reasons, (problems[0][1] if problems else None)


class CollectionMembershipInvalid(Rule):
    """A RenderPass collection fails validation or its membership cannot be computed.

    ## What it does
    For each of the RenderPass collections `renderVisibility`,
    `cameraVisibility`, `prune` and `matte`, reports one finding when
    `Usd.CollectionAPI.Validate()` fails (e.g. an invalid `expansionRule`, or
    collections that include each other), when the authored
    `membershipExpression` references another collection (`%/path:name`, or
    `%:name` on the pass itself) that does not exist, or when
    `ComputeMembershipQuery()` raises (e.g. *No registered function 'type'*
    for an unknown predicate). A syntax error in a `pathExpression` never
    reaches this rule: usd-core rejects the file while parsing (ST001).

    ## Why is this bad?
    *"the set of objects visible in the render is specified via the
    renderVisibility collection"* (`pxr/usd/usdRender/schema.usda`,
    RenderPass). An expression that cannot be evaluated leaves the pass's
    visibility undefined, and a dangling collection reference silently
    becomes an empty set.

    ## Example
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Mesh "hero"
        {
        }
    }

    def Scope "Render"
    {
        def RenderPass "hero"
        {
            uniform token passType = "prman"
            uniform token collection:renderVisibility:mode = "expression"
            uniform pathExpression collection:renderVisibility:membershipExpression = "/World//{type:Mesh}"
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Mesh "hero"
        {
        }
    }

    def Scope "Render"
    {
        def RenderPass "hero"
        {
            uniform token passType = "prman"
            uniform token collection:renderVisibility:mode = "expression"
            uniform pathExpression collection:renderVisibility:membershipExpression = "/World//{isa:Mesh}"
        }
    }
    ```

    ## Fix safety
    No automatic fix: the intended predicate or collection is unknown.
    """  # noqa: E501 - usda lines in the examples cannot wrap

    code = "PA005"
    name = "collection-membership-invalid"
    severity = Severity.ERROR
    partial_composition = True
    prim_types = (schemas.RenderPass,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        for collection in authored_pass_collections(prim, ctx):
            reasons, anchor = _collection_problems(collection)
            if reasons:
                yield Diagnostic(
                    message=f"{collection_label(collection)} on {prim.GetPath()} is invalid: "
                    f"{'; '.join(reasons)}; correct it so the pass's membership is defined",
                    at=anchor if anchor and anchor.IsAuthored() else prim,
                )
