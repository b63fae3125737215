"""PA005 collection-membership-invalid."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Tf, Usd

from usdrender_lint.api import Context, Diagnostic, Rule, Severity, schemas
from usdrender_lint.api.resolve import PrimValues, prim_values

from .._passes import (
    authored_pass_collections,
    missing_expression_references,
    usd_error_text,
)


def _collection_problems(
    values: PrimValues, collection: Usd.CollectionAPI, label: str
) -> tuple[list[str], Usd.Property | None]:
    """Why a collection (named ``label``, "collection:<name>") of the pass whose
    values are ``values`` cannot be trusted, and the property the first
    problem is about."""
    # By name: the pass's values answer from the authored names (most passes
    # author no expression), and a property is looked up only for a finding.
    expression_name = f"{label}:membershipExpression"
    expression = values.authored(expression_name)
    # Evaluation errors (e.g. an unknown predicate) can surface from Validate()
    # as well as from ComputeMembershipQuery(): report them once.
    evaluation_anchor = expression_name if expression is not None else f"{label}:includes"
    problems: list[tuple[str, str]] = []

    def evaluation_failed(exc: Tf.ErrorException) -> None:
        text = f"its membership cannot be computed: {usd_error_text(exc)}"
        problems.append((text, evaluation_anchor))

    try:
        # Unbound: the collections are of usable passes (no validity check per call).
        valid, why = Usd.CollectionAPI.Validate(collection)
        if not valid:
            anchor = f"{label}:expansionRule" if "expansionRule" in why else f"{label}:includes"
            problems.append((why.strip().rstrip(".") or "Validate() failed", anchor))
    except Tf.ErrorException as exc:
        evaluation_failed(exc)
    if expression is not None and not expression.IsEmpty():
        for path in missing_expression_references(collection, expression):
            text = (
                f"its membershipExpression references the collection <{path}>, which does "
                "not exist (USD substitutes an empty expression)"
            )
            problems.append((text, expression_name))
    # Validate() already ran the membership computation (both call
    # _ComputeMembershipQueryImpl, pxr/usd/usd/collectionAPI.cpp); only an
    # expression is evaluated by ComputeMembershipQuery() alone (an unknown
    # predicate raises there). Without an expression opinion it has nothing to add.
    if values.may_be_authored(expression_name):
        try:
            Usd.CollectionAPI.ComputeMembershipQuery(collection)
        except Tf.ErrorException as exc:
            evaluation_failed(exc)
    if not problems:
        return [], None
    reasons = list(dict.fromkeys(text for text, _ in problems))
    first = problems[0][1]
    # The includes are a relationship, the others attributes.
    anchor = values.relationship(first) if first.endswith(":includes") else values.attribute(first)
    return reasons, anchor


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
        values = prim_values(prim)
        for label, collection in authored_pass_collections(prim, ctx):
            reasons, anchor = _collection_problems(values, collection, label)
            if reasons:
                yield Diagnostic(
                    message=f"{label} on {prim.GetPath()} is invalid: "
                    f"{'; '.join(reasons)}; correct it so the pass's membership is defined",
                    at=anchor if anchor and anchor.IsAuthored() else prim,
                )
