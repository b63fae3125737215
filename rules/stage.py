"""ST: stage-wide checks (opening, composition, which settings render)."""

from __future__ import annotations

from collections.abc import Iterator

from pxr import Sdf, Usd, UsdGeom, UsdRender

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity
from usdrender_lint.resolve import describe_prim_type, forwarded_targets, unusable_reason

#: The renderSettingsPrimPath layer-metadata field (pseudo-root of a layer).
RENDER_SETTINGS_PATH_KEY = "renderSettingsPrimPath"
#: The usdRender naming convention: render prims live under this root prim.
RENDER_SCOPE = Sdf.Path("/Render")
#: Concrete usdRender type names, the candidates for a misspelt type.
RENDER_TYPE_NAMES = ("RenderSettings", "RenderProduct", "RenderVar", "RenderPass")
RENDER_SCHEMAS = (UsdRender.SettingsBase, UsdRender.Var, UsdRender.Pass)


def settings_path_opinion(ctx: Context) -> tuple[str, Sdf.Layer] | None:
    """The renderSettingsPrimPath value that counts and the layer authoring it.

    Only the session and root layers' metadata is stage metadata (catalog,
    Ambiguous semantics 8; a sublayer's opinion is invisible to
    ``stage.GetMetadata``); the session layer is the stronger. Read once per
    lint: five ST rules ask."""

    def compute() -> tuple[str, Sdf.Layer] | None:
        stage = ctx.stage
        for layer in (stage.GetSessionLayer(), stage.GetRootLayer()):
            if layer is not None and layer.pseudoRoot.HasInfo(RENDER_SETTINGS_PATH_KEY):
                return str(layer.pseudoRoot.GetInfo(RENDER_SETTINGS_PATH_KEY)), layer
        return None

    return ctx.memo("stage.settings_path_opinion", compute)


def _set_settings_path(value: str):
    def apply(stage: Usd.Stage) -> None:
        # Stage metadata goes to the edit target, which must be the root or session layer.
        stage.SetMetadata(RENDER_SETTINGS_PATH_KEY, value)

    return apply


def _single_settings_fix(ctx: Context, what: str) -> Fix | None:
    """Point renderSettingsPrimPath at the stage's only usable RenderSettings."""
    settings = ctx.prims_of(UsdRender.Settings)
    if len(settings) != 1:
        return None
    path = str(settings[0].GetPath())
    return Fix(
        f'{what} renderSettingsPrimPath = "{path}" in the root layer',
        True,
        _set_settings_path(path),
        layer=ctx.stage.GetRootLayer(),
    )


def edit_distance(a: str, b: str) -> int:
    """Levenshtein distance: insertions, deletions and substitutions."""
    previous = list(range(len(b) + 1))
    for i, char_a in enumerate(a, 1):
        current = [i]
        for j, char_b in enumerate(b, 1):
            current.append(
                min(previous[j] + 1, current[j - 1] + 1, previous[j - 1] + (char_a != char_b))
            )
        previous = current
    return previous[-1]


def is_render_type(prim: Usd.Prim) -> bool:
    return any(prim.IsA(schema) for schema in RENDER_SCHEMAS)


class StageOpenFailed(Rule):
    """The file cannot be opened as a USD stage.

    ## What it does
    Reports each error USD raises while opening the file (`Usd.Stage.Open`),
    with the file, line and column USD gives. The engine emits this finding
    itself when the open fails and then runs no other rule on the file; it is
    reported even when not selected, so a broken file is never a silent pass.

    ## Why is this bad?
    Nothing else can be checked on a stage that does not compose, and the
    renderer cannot open it either. The official
    `pxr/usd/usdRender/doxygen/renderSettings.usda` example begins with
    `#usda1.0`, which usd-core 26.11 rejects: *"Invalid layer header '#usda1.0'
    does not start with '#usda '"*.

    ## Example
    ```usda
    #usda1.0

    def Scope "Render"
    {
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
    }
    ```

    ## Fix safety
    No automatic fix: repair the file by hand at the line and column reported.
    """

    code = "ST001"
    name = "stage-open-failed"
    severity = Severity.ERROR


def _composition_error_site(error) -> Sdf.Path | None:
    site = getattr(error, "rootSite", None)
    path = getattr(site, "path", None)
    return path if isinstance(path, Sdf.Path) else None


def _render_prim_paths(stage: Usd.Stage) -> list[Sdf.Path]:
    """Paths of every render prim, inactive, `over` and abstract ones included
    (``TraverseAll``); the schema test is cached per type name."""
    by_type_name: dict[str, bool] = {}
    paths = []
    for prim in stage.TraverseAll():
        type_name = prim.GetTypeName()
        hit = by_type_name.get(type_name)
        if hit is None:
            hit = by_type_name[type_name] = is_render_type(prim)
        if hit:
            paths.append(prim.GetPath())
    return paths


class CompositionErrorOnRenderPrim(Rule):
    """A composition error hits a render prim, its ancestors or descendants, or /Render.

    ## What it does
    Reports each of `stage.GetCompositionErrors()` whose site is under
    `/Render`, or is a RenderSettings, RenderProduct, RenderVar or RenderPass
    (inactive ones included), or an ancestor or descendant of one. Layer-stack
    errors such as a missing sublayer have the site `/`, an ancestor of every
    prim, so they are always reported. The message is USD's own.

    ## Why is this bad?
    A render prim whose reference, payload or inherit fails to compose
    silently loses every opinion that arc supplies: a facility RenderSettings
    referenced from a shared layer reverts to schema fallbacks (2048x1080, no
    camera, no products). OpenUSD reports it only as a stage warning (*"Could
    not open asset @...@ for reference introduced by ..."*,
    `pxr/usd/usd/stage.cpp`), which CI logs usually ignore.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings" (
            references = @./facility/shot_render_settings.usda@</Render/Settings>
        )
        {
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
            uniform int2 resolution = (1920, 1080)
        }
    }
    ```

    ## Fix safety
    No automatic fix: repair the asset path or remove the arc.
    """

    code = "ST002"
    name = "composition-error-on-render-prim"
    severity = Severity.ERROR

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        errors = ctx.stage.GetCompositionErrors()
        if not errors:
            return
        render_paths: list[Sdf.Path] | None = None
        for error in errors:
            site = _composition_error_site(error)
            if site is None:
                continue
            if site != Sdf.Path.absoluteRootPath and not site.HasPrefix(RENDER_SCOPE):
                if render_paths is None:
                    render_paths = _render_prim_paths(ctx.stage)
                if not any(site.HasPrefix(p) or p.HasPrefix(site) for p in render_paths):
                    continue
            at_root = site == Sdf.Path.absoluteRootPath
            scope = "every prim" if at_root else f"render data at <{site}>"
            yield Diagnostic(
                f"{' '.join(str(error).split())} {scope[0].upper()}{scope[1:]} loses the "
                "opinions this layer or arc would supply; repair the asset path or remove it",
                at=None if at_root else site,
            )


class RenderSettingsPathMissing(Rule):
    """The stage has one RenderSettings but no renderSettingsPrimPath names it.

    ## What it does
    Reports a stage whose root and session layers author no (or an empty)
    `renderSettingsPrimPath` while it holds exactly one usable RenderSettings.

    ## Why is this bad?
    *"Always provide a 'default' RenderSettings. ... Communicate to a renderer
    what the default RenderSettings is by using the `renderSettingsPrimPath`
    metadata in your stage's root layer"* (`pxr/usd/usdRender/userDoc/overview.md`).
    `UsdRenderSettings::GetStageRenderSettings()` consults only this metadata
    (`pxr/usd/usdRender/settings.cpp`) and returns nothing without it.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0
    (
        renderSettingsPrimPath = "/Render/Settings"
    )

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
        }
    }
    ```

    ## Fix safety
    Safe: the fix authors `renderSettingsPrimPath` naming the only
    RenderSettings in the root layer's metadata (never in a sublayer, where
    it is ignored; see ST007).
    """

    code = "ST003"
    name = "render-settings-path-missing"
    severity = Severity.INFO
    fix_safety = "safe"

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        opinion = settings_path_opinion(ctx)
        settings = ctx.prims_of(UsdRender.Settings)
        if (opinion is not None and opinion[0]) or len(settings) != 1:
            return
        path = settings[0].GetPath()
        state = "is empty" if opinion is not None else "is not set"
        yield Diagnostic(
            f"stage metadata renderSettingsPrimPath {state}, so "
            f"UsdRenderSettings.GetStageRenderSettings() finds no settings although the stage "
            f'has one, <{path}>; author renderSettingsPrimPath = "{path}" in the root layer',
            fix=_single_settings_fix(ctx, "author"),
        )


class RenderSettingsAmbiguous(Rule):
    """Several RenderSettings and no renderSettingsPrimPath choosing one.

    ## What it does
    Reports a stage whose root and session layers author no (or an empty)
    `renderSettingsPrimPath` while it holds two or more usable RenderSettings,
    and lists them.

    ## Why is this bad?
    *"A UsdStage may contain multiple UsdRenderSettings prims representing
    distinct groups of settings. A settings prim may be nominated as a useful
    default in layer metadata using the `renderSettingsPrimPath` field."*
    (`pxr/usd/usdRender/overview.dox`). Without it every tool picks its own
    (first found, last found, or none), so farm and viewport renders differ.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Final"
        {
        }

        def RenderSettings "Preview"
        {
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0
    (
        renderSettingsPrimPath = "/Render/Final"
    )

    def Scope "Render"
    {
        def RenderSettings "Final"
        {
        }

        def RenderSettings "Preview"
        {
        }
    }
    ```

    ## Fix safety
    No automatic fix: a person must choose the default settings.
    """

    code = "ST004"
    name = "render-settings-ambiguous"
    severity = Severity.WARNING

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        opinion = settings_path_opinion(ctx)
        settings = ctx.prims_of(UsdRender.Settings)
        if (opinion is not None and opinion[0]) or len(settings) < 2:
            return
        candidates = ", ".join(f"<{p.GetPath()}>" for p in settings)
        yield Diagnostic(
            f"the stage has {len(settings)} RenderSettings ({candidates}) and no "
            "renderSettingsPrimPath, so each tool picks its own; author "
            "renderSettingsPrimPath in the root layer naming the default one",
        )


def _settings_path_problem(stage: Usd.Stage, value: str) -> str | None:
    """Why a non-empty renderSettingsPrimPath names no prim (ST005), or None."""
    if not Sdf.Path.IsValidPathString(value):
        return "is not a valid path"
    path = Sdf.Path(value)
    if not path.IsAbsolutePath():
        return "is relative (it must be absolute)"
    if not path.IsPrimPath():
        return "is not a prim path"
    if not stage.GetPrimAtPath(path):
        return "names no prim on the composed stage"
    return None


class RenderSettingsPathUnresolved(Rule):
    """renderSettingsPrimPath names no prim.

    ## What it does
    Reports an authored, non-empty `renderSettingsPrimPath` (root or session
    layer) that is not a valid path, is relative (`Render/Settings`), is not a
    prim path (a property path, `/`), or names no prim on the composed stage.

    ## Why is this bad?
    The metadata *"encodes the path to UsdRenderSettingsPrim to use for
    rendering"* (`pxr/usd/usdRender/schema.usda`);
    `UsdRenderSettings::GetStageRenderSettings()` returns an invalid prim *"If
    unauthored, or the metadata does not refer to a valid UsdRenderSettings
    prim"* (`pxr/usd/usdRender/settings.h`), and the render silently uses
    renderer defaults.

    ## Example
    ```usda
    #usda 1.0
    (
        renderSettingsPrimPath = "/Render/PrimarySettings"
    )

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0
    (
        renderSettingsPrimPath = "/Render/Settings"
    )

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when the stage has exactly one usable RenderSettings and
    the value is authored in the root layer, the fix rewrites it to name that
    prim. Otherwise there is no fix.
    """

    code = "ST005"
    name = "render-settings-path-unresolved"
    severity = Severity.ERROR
    fix_safety = "safe-conditional"

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        opinion = settings_path_opinion(ctx)
        if opinion is None or not opinion[0]:
            return
        value, layer = opinion
        problem = _settings_path_problem(ctx.stage, value)
        if problem is None:
            return
        fix = _single_settings_fix(ctx, "rewrite to") if layer == ctx.stage.GetRootLayer() else None
        yield Diagnostic(
            f'renderSettingsPrimPath "{value}" {problem}, so renderers find no default '
            "RenderSettings; name an existing RenderSettings prim by its absolute path",
            layer=layer,
            fix=fix,
        )


class RenderSettingsPathNotRenderSettings(Rule):
    """renderSettingsPrimPath names a prim that is not a usable RenderSettings.

    ## What it does
    Reports an authored `renderSettingsPrimPath` naming an existing prim that
    is not a RenderSettings (a RenderProduct, a Scope, ...), or a RenderSettings
    that is inactive, only an `over`, or abstract (a `class`).

    ## Why is this bad?
    `UsdRenderSettings::GetStageRenderSettings()` returns an invalid prim *"If
    unauthored, or the metadata does not refer to a valid UsdRenderSettings
    prim"* (`pxr/usd/usdRender/settings.h`). For an inactive or abstract
    RenderSettings it still returns a valid object (usd-core 26.11), but Hydra
    never populates such prims, so consumers disagree.

    ## Example
    ```usda
    #usda 1.0
    (
        renderSettingsPrimPath = "/Render/Product"
    )

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel products = </Render/Product>
        }

        def RenderProduct "Product"
        {
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0
    (
        renderSettingsPrimPath = "/Render/Settings"
    )

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
            rel products = </Render/Product>
        }

        def RenderProduct "Product"
        {
        }
    }
    ```

    ## Fix safety
    No automatic fix: which settings was meant is unknown.
    """

    code = "ST006"
    name = "render-settings-path-not-render-settings"
    severity = Severity.ERROR

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        opinion = settings_path_opinion(ctx)
        if opinion is None or not opinion[0]:
            return
        value, layer = opinion
        if _settings_path_problem(ctx.stage, value) is not None:
            return  # ST005's finding
        prim = ctx.stage.GetPrimAtPath(value)
        if not prim.IsA(UsdRender.Settings):
            what = f"{describe_prim_type(prim)}, not a RenderSettings"
        else:
            reason = unusable_reason(prim)
            if reason is None:
                return
            what = f"a RenderSettings that {reason}"
        yield Diagnostic(
            f'renderSettingsPrimPath "{value}" names {what}; renderers find no usable '
            "default settings. Name a defined, active RenderSettings prim",
            layer=layer,
        )


def _root_layer_stack_rank(stage: Usd.Stage) -> dict[Sdf.Layer, int]:
    return {layer: rank for rank, layer in enumerate(stage.GetLayerStack(False))}


class RenderSettingsPathInSublayer(Rule):
    """renderSettingsPrimPath is authored in a layer whose metadata the stage ignores.

    ## What it does
    Reports every layer the stage uses, other than its root and session
    layers, whose metadata authors a non-empty `renderSettingsPrimPath`:
    sublayers, and referenced or payloaded layers. Composition ignores that
    opinion (`stage.GetMetadata` does not see it). A value the root or session
    layer already authors identically is redundant, not lost, and is not
    reported (that is also what the fix leaves behind).

    ## Why is this bad?
    *"Like all stage metadata, `renderSettingsPrimPath` can be authoredin a
    stage's root layer or session layer, but no other subLayers of the root
    layer."* (`pxr/usd/usdRender/overview.dox`, typo verbatim). Shot layers
    that sublayer a sequence render layer lose its default settings without
    any message.

    ## Example
    ```usda
    #usda 1.0
    (
        subLayers = [
            @./render_layer.usda@
        ]
    )
    ```

    with `render_layer.usda`:

    ```usda render_layer.usda
    #usda 1.0
    (
        renderSettingsPrimPath = "/Render/Settings"
    )

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0
    (
        renderSettingsPrimPath = "/Render/Settings"
    )

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when neither the root nor the session layer authors the
    field, the fix copies the strongest sublayer's value into the root layer
    metadata (the sublayer opinion is inert and may stay). Otherwise, and for
    referenced layers, there is no fix.
    """

    code = "ST007"
    name = "render-settings-path-in-sublayer"
    severity = Severity.WARNING
    fix_safety = "safe-conditional"

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        stage = ctx.stage
        ignored = {stage.GetRootLayer(), stage.GetSessionLayer()}
        rank = _root_layer_stack_rank(stage)
        inert = [
            (layer, str(layer.pseudoRoot.GetInfo(RENDER_SETTINGS_PATH_KEY)))
            for layer in stage.GetUsedLayers()
            if layer not in ignored and layer.pseudoRoot.HasInfo(RENDER_SETTINGS_PATH_KEY)
        ]
        opinion = settings_path_opinion(ctx)
        effective = opinion[0] if opinion is not None else None
        inert = [(layer, value) for layer, value in inert if value and value != effective]
        inert.sort(key=lambda item: (rank.get(item[0], len(rank)), item[0].identifier))
        # Only the strongest sublayer opinion is what the author most likely meant.
        fixable = opinion is None and inert and inert[0][0] in rank
        for index, (layer, value) in enumerate(inert):
            fix = None
            if fixable and index == 0:
                fix = Fix(
                    f'copy renderSettingsPrimPath = "{value}" into the root layer',
                    True,
                    _set_settings_path(value),
                    layer=stage.GetRootLayer(),
                )
            kind = "sublayer" if layer in rank else "referenced layer"
            advice = (
                "author it in the root layer"
                if effective is None
                else f'the stage uses "{effective}"; remove the ignored value'
            )
            yield Diagnostic(
                f'renderSettingsPrimPath "{value}" is authored in the {kind} '
                f"{layer.GetDisplayName()}, where the stage ignores it (only the root and session "
                f"layers count); {advice}",
                layer=layer,
                fix=fix,
            )


def _is_locally_authored(prim: Usd.Prim) -> bool:
    """Every opinion on the prim sits at its own path in the stage's layer stack."""
    stage = prim.GetStage()
    return all(
        spec.path == prim.GetPath() and stage.HasLocalLayer(spec.layer)
        for spec in prim.GetPrimStack()
    )


def _move_under_render_scope(source: Sdf.Path, destination: Sdf.Path):
    def apply(stage: Usd.Stage) -> None:
        if not stage.GetPrimAtPath(RENDER_SCOPE):
            UsdGeom.Scope.Define(stage, RENDER_SCOPE)
        editor = Usd.NamespaceEditor(stage)
        if not (editor.MovePrimAtPath(source, destination) and editor.ApplyEdits()):
            raise RuntimeError(f"could not move <{source}> to <{destination}>")

    return apply


class RenderPrimOutsideRenderScope(Rule):
    """A render prim lives outside /Render.

    ## What it does
    Reports a usable RenderSettings, RenderProduct, RenderVar or RenderPass
    whose path is not under `/Render`.

    ## Why is this bad?
    *"UsdRender follows a naming convention that all render settings in the
    scene must live under the path `</Render>`"* so that
    `UsdStage::OpenMasked()` can compose just the render data
    (`pxr/usd/usdRender/overview.dox`); the user guide softens it to a best
    practice (`docs/user_guides/render_user_guide.rst`), hence info.

    ## Example
    ```usda
    #usda 1.0

    def RenderSettings "Settings"
    {
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
    }
    ```

    ## Fix safety
    Unsafe: the fix moves the prim under `/Render` with `Usd.NamespaceEditor`
    (creating a `/Render` Scope when needed), offered only for the outermost
    render prim and when `/Render/<name>` is free. Relationships and external
    references to the old path are not updated.
    """

    code = "ST008"
    name = "render-prim-outside-render-scope"
    severity = Severity.INFO
    fix_safety = "unsafe"
    prim_types = RENDER_SCHEMAS

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        path = prim.GetPath()
        if path.HasPrefix(RENDER_SCOPE):
            return
        destination = RENDER_SCOPE.AppendChild(prim.GetName())
        fix = None
        # A nested render prim moves with its render-prim parent; a prim that
        # a reference or other arc brings in cannot be moved by editing this stage.
        if (
            not is_render_type(prim.GetParent())
            and not ctx.stage.GetPrimAtPath(destination)
            and _is_locally_authored(prim)
        ):
            fix = Fix(
                f"move to <{destination}> (targets of the old path are not updated)",
                False,
                _move_under_render_scope(path, destination),
            )
        yield Diagnostic(
            f"{prim.GetTypeName()} <{path}> is outside </Render>; the usdRender "
            "convention keeps render prims under </Render> so that masked stages compose "
            "them alone. Move it under </Render>",
            at=prim,
            fix=fix,
        )


class UnreferencedRenderPrim(Rule):
    """A RenderProduct or RenderVar that nothing renders.

    ## What it does
    Reports a usable RenderProduct that is not among the forwarded `products`
    targets of any RenderSettings, and a usable RenderVar that is not among the
    forwarded `orderedVars` targets of any RenderProduct.

    ## Why is this bad?
    `UsdRenderComputeSpec` reaches products only through
    `settings.GetProductsRel().GetForwardedTargets()` and vars only through
    `GetOrderedVarsRel()` (`pxr/usd/usdRender/spec.cpp`): orphans are dead data
    and usually mean a renamed or forgotten connection.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSettings "Settings"
        {
        }

        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
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
            rel products = </Render/Beauty>
        }

        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
        }
    }
    ```

    ## Fix safety
    No automatic fix: another settings layer may still want the prim.
    """

    code = "ST009"
    name = "unreferenced-render-prim"
    severity = Severity.INFO

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for product in ctx.untargeted_products:
            yield Diagnostic(
                f"RenderProduct <{product.GetPath()}> is in no RenderSettings' products, so "
                "nothing renders it; add it to a RenderSettings' products or remove it",
                at=product,
            )
        targeted = {
            path
            for product in ctx.prims_of(UsdRender.Product)
            for path in forwarded_targets(product.GetRelationship("orderedVars"))
        }
        for var in ctx.prims_of(UsdRender.Var):
            if var.GetPath() not in targeted:
                yield Diagnostic(
                    f"RenderVar <{var.GetPath()}> is in no RenderProduct's orderedVars, so "
                    "no product outputs it; add it to a product's orderedVars or remove it",
                    at=var,
                )


def _retype(prim_path: Sdf.Path, type_name: str):
    def apply(stage: Usd.Stage) -> None:
        stage.GetPrimAtPath(prim_path).SetTypeName(type_name)

    return apply


def _type_name_spec(prim: Usd.Prim) -> Sdf.PrimSpec | None:
    """The strongest spec authoring the prim's type name."""
    return next((spec for spec in prim.GetPrimStack() if spec.typeName), None)


class UnknownRenderPrimType(Rule):
    """A prim under /Render, or with a Render... type name, has an unregistered type.

    ## What it does
    Reports a usable prim whose type name is not empty but names no registered
    schema, when the prim is under `/Render` or its type name starts with
    `Render` (any case). It suggests the closest usdRender type name
    (`RenderSettings`, `RenderProduct`, `RenderVar`, `RenderPass`) by edit
    distance.

    ## Why is this bad?
    USD composes an unknown type as a typeless prim, so `def RenderSetting` or
    `def RenderVars` is not a RenderSettings or RenderVar and every schema-based
    consumer skips it (`IsA` is false; usd-core 26.11). It also fires when the
    renderer plugin that registers a custom render type is not installed where
    you lint.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderSetting "Settings"
        {
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
    }
    ```

    ## Fix safety
    Unsafe: when exactly one usdRender type is closest and within edit distance
    2, the fix rewrites the type name in the layer of the stage's layer stack
    that authors it; the prim then starts to take part in renders. Otherwise
    (or when the type comes through a reference) there is no fix.
    """

    code = "ST010"
    name = "unknown-render-prim-type"
    severity = Severity.WARNING
    fix_safety = "unsafe"

    #: Farther than this, a usdRender type name is no plausible suggestion.
    suggestion_distance = 3
    fix_distance = 2

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        for prim in ctx.unknown_type_prims:
            type_name = prim.GetTypeName()
            path = prim.GetPath()
            if not (path.HasPrefix(RENDER_SCOPE) or type_name.lower().startswith("render")):
                continue
            ranked = sorted((edit_distance(type_name, c), c) for c in RENDER_TYPE_NAMES)
            (distance, closest), (runner_up, _) = ranked[0], ranked[1]
            if distance <= self.suggestion_distance:
                advice = f"did you mean {closest}?"
            else:
                advice = (
                    "if a renderer plugin defines this type, install it where you lint; "
                    "otherwise use a usdRender type"
                )
            fix = None
            spec = _type_name_spec(prim)
            if (
                distance <= self.fix_distance
                and runner_up > distance
                and spec is not None
                and spec.path == path
                and ctx.stage.HasLocalLayer(spec.layer)
            ):
                fix = Fix(
                    f"retype <{path}> as {closest}",
                    False,
                    _retype(path, closest),
                    layer=spec.layer,
                )
            what = "is not a registered schema here"
            if not Usd.SchemaRegistry.GetTypeFromName(type_name).isUnknown:
                # e.g. `def RenderSettingsBase`: registered, but abstract.
                what = "is an abstract schema, which cannot type a prim"
                advice = f"use a concrete type such as {closest}"
            yield Diagnostic(
                f"type '{type_name}' of <{path}> {what}, so USD "
                f"composes it as a typeless prim that schema-based consumers skip; {advice}",
                at=prim,
                fix=fix,
                layer=spec.layer if spec is not None else None,
            )


RULES = (
    StageOpenFailed,
    CompositionErrorOnRenderPrim,
    RenderSettingsPathMissing,
    RenderSettingsAmbiguous,
    RenderSettingsPathUnresolved,
    RenderSettingsPathNotRenderSettings,
    RenderSettingsPathInSublayer,
    RenderPrimOutsideRenderScope,
    UnreferencedRenderPrim,
    UnknownRenderPrimType,
)
