"""PA: RenderPass prims, their sources, dependencies and collections."""

from __future__ import annotations

import re
from collections.abc import Iterator

from pxr import Sdf, Tf, Usd, UsdRender

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity
from usdrender_lint.resolve import (
    DEFAULT_TIME,
    authored_targets,
    authored_value,
    has_authored_value,
    is_usable,
    mismatched_spec,
    resolve_targets,
    typed_target_problem,
)

from ._passes import (
    authored_pass_collections,
    collection_label,
    dangling_object_reason,
    find_cycles,
    input_pass_graph,
    missing_expression_references,
    usd_error_text,
)


def _authored_layer(attr: Usd.Attribute) -> Sdf.Layer | None:
    """The layer of the strongest spec holding the attribute's default value."""
    for spec in attr.GetPropertyStack(DEFAULT_TIME):
        if spec.HasDefaultValue():
            return spec.layer
    return None


def _value_lost_elsewhere(attr: Usd.Attribute) -> bool:
    """The Default-time value is lost to a mistake another rule reports: a
    mistyped opinion (SE016) or time samples with no default on a uniform
    attribute (SE017). Rules that read the value stay silent then, so one
    mistake gives one finding."""
    if mismatched_spec(attr) is not None:
        return True
    return attr.GetNumTimeSamples() > 0 and _authored_layer(attr) is None


# -- PA001 ------------------------------------------------------------------------


def _intended_absolute_settings(owner: Usd.Prim, target: Sdf.Path) -> Sdf.Path | None:
    """``/suffix`` when ``target`` is the owner's path + suffix and ``/suffix``
    is a usable RenderSettings: Sdf anchored a relative ``<suffix>`` to the
    owning prim (catalog, Ambiguous semantics 11)."""
    owner_path = owner.GetPath()
    if target == owner_path or not target.HasPrefix(owner_path) or not target.IsPrimPath():
        return None
    intended = Sdf.Path.absoluteRootPath.AppendPath(target.MakeRelativePath(owner_path))
    prim = owner.GetStage().GetPrimAtPath(intended)
    return intended if prim and is_usable(prim) and prim.IsA(UsdRender.Settings) else None


def _replace_target(rel_path: Sdf.Path, old: Sdf.Path, new: Sdf.Path):
    def apply(stage: Usd.Stage) -> None:
        rel = stage.GetRelationshipAtPath(rel_path)
        rel.SetTargets([new if t == old else t for t in rel.GetTargets()])

    return apply


class RenderSourceInvalid(Rule):
    """A RenderPass without a fileName has no valid RenderSettings renderSource.

    ## What it does
    For a RenderPass with no authored, non-empty `fileName`, reports a
    `renderSource` relationship with no forwarded target, and each forwarded
    target that is not a prim path, has no prim, is inactive, `over`-only or
    abstract, or is not a RenderSettings. With `fileName` authored the target
    may name an object in that external file (e.g. a Nuke write node) and is
    not checked. A relative target such as `<Render/PrimarySettings>` is
    anchored by Sdf to the pass itself, so it usually dangles; the message
    says so.

    ## Why is this bad?
    *"If fileName is not present, the source is assumed to be a RenderSettings
    prim present in the current Usd stage."* (`pxr/usd/usdRender/schema.usda`,
    RenderPass `renderSource`). A pass with no stage source cannot be rendered.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "PrimarySettings"
        {
        }

        def Scope "Passes"
        {
            def RenderPass "beauty"
            {
                uniform token passType = "prman"
                rel renderSource = <Render/PrimarySettings>
            }
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "PrimarySettings"
        {
        }

        def Scope "Passes"
        {
            def RenderPass "beauty"
            {
                uniform token passType = "prman"
                rel renderSource = </Render/PrimarySettings>
            }
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when a dangling target is the pass's own path plus a
    suffix and `/suffix` is a RenderSettings (the relative-path mistake above),
    the fix rewrites that target to `/suffix`. Otherwise there is no fix.
    """

    code = "PA001"
    name = "render-source-invalid"
    severity = Severity.ERROR
    fix_safety = "safe-conditional"
    prim_types = (UsdRender.Pass,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        # Read by name: a schema object costs ~1.2 us a pass and is not needed.
        file_attr = prim.GetAttribute("fileName")
        if _value_lost_elsewhere(file_attr):
            return  # A fileName was meant; SE016 or SE017 reports how it is lost.
        file_name = authored_value(file_attr)
        if file_name is not None and file_name.authoredPath:
            return
        rel = prim.GetRelationship("renderSource")
        targets = resolve_targets(rel)
        if not targets:
            yield Diagnostic(
                f"RenderPass {prim.GetPath()} has neither a fileName nor a renderSource "
                "target; point renderSource at the RenderSettings prim this pass renders, "
                "or author fileName when the source lives in another file",
                at=rel if rel.HasAuthoredTargets() else prim,
            )
            return
        for target in targets:
            problem = typed_target_problem(target, UsdRender.Settings, "a RenderSettings")
            if problem is None:
                continue
            intended = _intended_absolute_settings(prim, target.path)
            fix = None
            advice = "target a RenderSettings prim, or author fileName for an external source"
            if intended is not None:
                relative = target.path.MakeRelativePath(prim.GetPath())
                advice = (
                    f"it looks like the relative path <{relative}>, which Sdf anchors to the "
                    f"pass; write the absolute path <{intended}>"
                )
                if target.path in authored_targets(rel):
                    fix = Fix(
                        f"retarget renderSource to <{intended}>",
                        True,
                        _replace_target(rel.GetPath(), target.path, intended),
                    )
            yield Diagnostic(
                f"renderSource target <{target.path}> {problem}; {advice}", at=rel, fix=fix
            )


# -- PA002 ------------------------------------------------------------------------


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
    prim_types = (UsdRender.Pass,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        rel = prim.GetRelationship("inputPasses")
        for target in resolve_targets(rel):
            problem = typed_target_problem(target, UsdRender.Pass, "a RenderPass")
            if problem is not None:
                yield Diagnostic(
                    f"inputPasses target <{target.path}> {problem}; list only the RenderPass "
                    "prims this pass depends on",
                    at=rel,
                )


# -- PA003 ------------------------------------------------------------------------


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
                f"RenderPass {cycle[0]} {what}: {chain}; the pass graph cannot be "
                "scheduled; remove one of these dependencies",
                at=UsdRender.Pass(first).GetInputPassesRel(),
            )


# -- PA004 ------------------------------------------------------------------------

_VARIABLE = re.compile(r"\$\{(\w+)\}")


def _unresolvable_reason(value: Sdf.AssetPath, layer: Sdf.Layer | None) -> str:
    """Why an authored asset path has no resolved path, and what to do."""
    authored = value.authoredPath
    where = f" relative to {layer.GetDisplayName()}" if layer is not None else ""
    if Sdf.VariableExpression.IsExpression(authored):
        errors = Sdf.VariableExpression(authored).GetErrors()
        if errors:
            return (
                f"is a variable expression USD cannot evaluate ({'; '.join(errors)}); "
                "correct the expression"
            )
        # usd-core leaves an unset variable in the evaluated path as written.
        unset = sorted(set(_VARIABLE.findall(value.evaluatedPath)))
        if unset:
            names = ", ".join(unset)
            return (
                f"evaluates to {value.evaluatedPath!r}: expression variable(s) {names} not "
                "set; define them in the root layer's expressionVariables"
            )
        return (
            f"evaluates to {value.evaluatedPath!r}, which does not resolve{where}; "
            "create the file or correct the path"
        )
    return f"does not resolve{where}; create the file or correct the path"


class FileNameUnresolvable(Rule):
    """A RenderPass fileName does not resolve to an existing asset.

    ## What it does
    Reports an authored, non-empty RenderPass `fileName` whose resolved path
    is empty after composition: USD's asset resolver, with the stage's
    resolver context, anchors a relative path to the layer that authored the
    opinion. A variable expression (backquoted, with `${VAR}`) is evaluated by
    USD first; unset variables and expression errors are named in the
    message. The same value passes once the file exists next to that layer.

    ## Why is this bad?
    *"The asset that contains the rendering prims or other information needed
    to render this pass."* (`pxr/usd/usdRender/schema.usda`, RenderPass
    `fileName`), and *"If fileName is present, the source should be found in
    the file there."* (same file, `renderSource`). A source that cannot be
    found cannot be rendered.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderPass "composite"
        {
            uniform token passType = "nuke"
            uniform asset fileName = @./comp/final_composite.nk@
            uniform string[] command = ["nuke", "-x", "{fileName}"]
        }
    }
    ```

    ## Use instead
    Author `fileName` only with a path that resolves, or render a
    RenderSettings prim of this stage:

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
    No automatic fix: the file is missing or the path is wrong, and only the
    author knows which.
    """

    code = "PA004"
    name = "file-name-unresolvable"
    severity = Severity.ERROR
    prim_types = (UsdRender.Pass,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("fileName")
        value = authored_value(attr)
        if not isinstance(value, Sdf.AssetPath) or not value.authoredPath or value.resolvedPath:
            return
        reason = _unresolvable_reason(value, _authored_layer(attr))
        yield Diagnostic(
            f"fileName @{value.authoredPath}@ {reason}",
            at=attr,
        )


# -- PA005 ------------------------------------------------------------------------


def _collection_problems(
    collection: Usd.CollectionAPI,
) -> tuple[list[str], Usd.Property | None]:
    """Why a collection's membership cannot be trusted, and the property the
    first problem is about."""
    expression_attr = collection.GetMembershipExpressionAttr()
    expression = authored_value(expression_attr)
    includes = collection.GetIncludesRel()
    # Evaluation errors (e.g. an unknown predicate) can surface from Validate()
    # as well as from ComputeMembershipQuery(): report them once.
    evaluation_anchor = expression_attr if expression is not None else includes
    problems: list[tuple[str, Usd.Property]] = []

    def evaluation_failed(exc: Tf.ErrorException) -> None:
        text = f"its membership cannot be computed: {usd_error_text(exc)}"
        problems.append((text, evaluation_anchor))

    try:
        valid, why = collection.Validate()
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
        collection.ComputeMembershipQuery()
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
    prim_types = (UsdRender.Pass,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        for collection in authored_pass_collections(prim, ctx):
            reasons, anchor = _collection_problems(collection)
            if reasons:
                yield Diagnostic(
                    f"{collection_label(collection)} on {prim.GetPath()} is invalid: "
                    f"{'; '.join(reasons)}; correct it so the pass's membership is defined",
                    at=anchor if anchor and anchor.IsAuthored() else prim,
                )


# -- PA006 ------------------------------------------------------------------------


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
        f'author {label}:mode = "expression"',
        True,
        _author_expression_mode(collection.GetPrim().GetPath(), collection.GetName()),
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
    fix_safety = "safe-conditional"
    prim_types = (UsdRender.Pass,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        for collection in authored_pass_collections(prim, ctx):
            attr = collection.GetMembershipExpressionAttr()
            expression = authored_value(attr)
            if expression is None or expression.IsEmpty():
                continue
            try:
                if not _expression_ignored(collection):
                    continue
            except Tf.ErrorException:
                continue  # The expression cannot be evaluated at all: PA005's finding.
            label = collection_label(collection)
            yield Diagnostic(
                f'{label}:membershipExpression "{expression.GetText()}" is ignored because '
                f"the collection is in relationship mode ({_relationship_mode_reason(collection)})"
                f'; author {label}:mode = "expression" (or includeRoot = false)',
                at=attr,
                fix=_expression_mode_fix(collection),
            )


# -- PA007 ------------------------------------------------------------------------


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
    prim_types = (UsdRender.Pass,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("passType")
        if _value_lost_elsewhere(attr):
            return
        if authored_value(attr):
            return
        state = "is the empty token" if has_authored_value(attr) else "is not set"
        yield Diagnostic(
            f"passType of RenderPass {prim.GetPath()} {state}; author the pipeline's pass "
            'type (e.g. "prman", "nuke") so job submission can dispatch the pass',
            at=attr if has_authored_value(attr) else prim,
        )


# -- PA008 ------------------------------------------------------------------------


class CollectionTargetMissing(Rule):
    """A RenderPass collection includes or excludes a path that names nothing.

    ## What it does
    Reports each target of `collection:<name>:includes` or `:excludes`, for
    the four RenderPass collections, for which the composed stage has no prim
    or property (`stage.GetObjectAtPath`), or whose prim is inactive,
    `over`-only or abstract; the message says which, and names the inactive
    ancestor when that is why the path has no prim.

    ## Why is this bad?
    A RenderPass partitions *"scene contents across multiple images rendered
    from the scene"* (`pxr/usd/usdRender/schema.usda`, RenderPass). A
    dangling include silently drops objects from the pass (typically after a
    rename), a dangling exclude silently leaves them in.

    ## Example
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Xform "chars"
        {
        }
    }

    def Scope "Render"
    {
        def RenderPass "foreground"
        {
            uniform token passType = "prman"
            uniform bool collection:renderVisibility:includeRoot = 0
            prepend rel collection:renderVisibility:includes = </World/characters>
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Xform "chars"
        {
        }
    }

    def Scope "Render"
    {
        def RenderPass "foreground"
        {
            uniform token passType = "prman"
            uniform bool collection:renderVisibility:includeRoot = 0
            prepend rel collection:renderVisibility:includes = </World/chars>
        }
    }
    ```

    ## Fix safety
    No automatic fix: the renamed path is unknown.
    """

    code = "PA008"
    name = "collection-target-missing"
    severity = Severity.WARNING
    prim_types = (UsdRender.Pass,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        stage = prim.GetStage()
        for collection in authored_pass_collections(prim, ctx):
            label = collection_label(collection)
            for kind, rel, effect in (
                ("includes", collection.GetIncludesRel(), "drops these objects from"),
                ("excludes", collection.GetExcludesRel(), "leaves these objects in"),
            ):
                for target in authored_targets(rel):
                    reason = dangling_object_reason(stage, target)
                    if reason is not None:
                        yield Diagnostic(
                            f"{label}:{kind} target <{target}> {reason}; it silently "
                            f"{effect} the pass; retarget it or remove it",
                            at=rel,
                        )


RULES = (
    RenderSourceInvalid,
    InputPassesInvalidTarget,
    InputPassesCycle,
    FileNameUnresolvable,
    CollectionMembershipInvalid,
    CollectionExpressionIgnored,
    PassTypeEmpty,
    CollectionTargetMissing,
)
