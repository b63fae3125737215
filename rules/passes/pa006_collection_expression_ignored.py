"""PA006 collection-expression-ignored."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Tf, Usd

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, schemas
from usdrender_lint.api.resolve import (
    authored_targets,
    authored_value,
    has_authored_value,
    prim_values,
)

from .._passes import authored_pass_collections, collection_label
from ._default_value import _authored_layer


def _expression_ignored(collection: Usd.CollectionAPI) -> bool:
    """True when the membership query does not use the expression.

    usd-core 26.11 infers ``IsInExpressionMode()`` from the computed query (no
    path-expansion rule map), so an explicit ``mode = "relationship"`` with no
    includes reports expression mode although the expression is ignored
    (verified: its paths are not included)."""
    if authored_value(collection.GetModeAttr()) == "relationship":
        return True
    return not collection.IsInExpressionMode()


def _relationship_mode_reason(collection: Usd.CollectionAPI) -> str:
    mode = authored_value(collection.GetModeAttr())
    if mode == "relationship":
        return 'mode is "relationship"'
    if authored_targets(collection.GetIncludesRel()) or authored_targets(
        collection.GetExcludesRel()
    ):
        return "it has includes/excludes targets"
    if has_authored_value(collection.GetIncludeRootAttr()):
        return "includeRoot is authored true"
    return "the RenderPass schema's includeRoot fallback is true"


def _author_expression_mode(prim_path: Sdf.Path, name: str):
    def apply(stage: Usd.Stage) -> None:
        Usd.CollectionAPI(stage.GetPrimAtPath(prim_path), name).CreateModeAttr().Set("expression")

    return apply


def _expression_mode_fix(collection: Usd.CollectionAPI) -> Fix | None:
    """Author mode = "expression" when nothing else says relationships were
    meant: no includes/excludes targets, no includeRoot, mode automatic."""
    if authored_targets(collection.GetIncludesRel()) or authored_targets(
        collection.GetExcludesRel()
    ):
        return None
    if collection.GetIncludeRootAttr().HasAuthoredValue():
        return None
    if authored_value(collection.GetModeAttr()) not in (None, "automatic"):
        return None
    label = collection_label(collection)
    return Fix(
        description=f'author {label}:mode = "expression"',
        safe=True,
        apply=_author_expression_mode(collection.GetPrim().GetPath(), collection.GetName()),
        layer=_authored_layer(collection.GetMembershipExpressionAttr()),
    )


class CollectionExpressionIgnored(Rule):
    """A RenderPass collection's membershipExpression is ignored (relationship mode).

    ## What it does
    Reports a RenderPass collection with an authored, non-empty
    `membershipExpression` while `CollectionAPI.IsInExpressionMode()` is
    false or `mode` is explicitly `"relationship"` (usd-core 26.11 reports
    expression mode for a relationship-mode collection without includes, yet
    ignores the expression). On `renderVisibility` and `cameraVisibility` that is what happens by
    default: the RenderPass schema overrides their `includeRoot` fallback to
    `true`, and in the fallback `mode = "automatic"` that fallback alone puts
    the collection in relationship mode (verified with usd-core 26.11), so the
    expression is ignored and the pass renders everything.

    ## Why is this bad?
    *"To use membershipExpression, includeRoot should be overridden to
    false."* (`pxr/usd/usdRender/schema.usda`, RenderPass). The expression the
    author wrote has no effect on what renders.

    ## Example
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Xform "Background_grp"
        {
        }
    }

    def Scope "Render"
    {
        def RenderPass "background"
        {
            uniform token passType = "prman"
            uniform pathExpression collection:renderVisibility:membershipExpression = "/World/Background*"
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Xform "Background_grp"
        {
        }
    }

    def Scope "Render"
    {
        def RenderPass "background"
        {
            uniform token passType = "prman"
            uniform token collection:renderVisibility:mode = "expression"
            uniform pathExpression collection:renderVisibility:membershipExpression = "/World/Background*"
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when the collection has no includes/excludes targets,
    no authored `includeRoot` and its mode is unauthored or `"automatic"`, the
    fix authors `mode = "expression"` in the layer that authors the
    expression (what the author meant). Otherwise the intent is mixed and
    there is no fix.
    """  # noqa: E501 - usda lines in the examples cannot wrap

    code = "PA006"
    name = "collection-expression-ignored"
    severity = Severity.WARNING
    partial_composition = True
    fix_safety = "safe-conditional"
    prim_types = (schemas.RenderPass,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        values = prim_values(prim)
        for label, collection in authored_pass_collections(prim, ctx):
            # By name: the pass's values answer from its authored names (most
            # collections have no expression), no property handle needed.
            expression_name = f"{label}:membershipExpression"
            expression = values.authored(expression_name)
            if expression is None or expression.IsEmpty():
                continue
            attr = values.attribute(expression_name)
            try:
                if not _expression_ignored(collection):
                    continue
            except Tf.ErrorException:
                continue  # The expression cannot be evaluated at all: PA005's finding.
            yield Diagnostic(
                message=f'{label}:membershipExpression "{expression.GetText()}" is ignored because '
                f"the collection is in relationship mode ({_relationship_mode_reason(collection)})"
                f'; author {label}:mode = "expression" (or includeRoot = false)',
                at=attr,
                fix=_expression_mode_fix(collection),
            )
