"""VA: RenderVar checks."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from dataclasses import dataclass
from functools import cache

from pxr import Sdf, Usd, UsdGeom, UsdRender

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity
from usdrender_lint.resolve import (
    allowed_tokens,
    authored_value,
    has_authored_value,
    mismatched_spec,
)

from ._aov import AovNaming, channel_name, checked_value, product_render_vars
from ._corrections import set_value, unique_case_match
from ._lpe import Dialect, lpe_problem, strip_renderer_prefix


class SourceNameEmpty(Rule):
    """A RenderVar's sourceName is empty.

    ## What it does
    Reports a usable RenderVar whose composed `sourceName` (`uniform string`,
    fallback `""`) is empty: left unauthored, authored `""` or blocked. A
    type-mismatched opinion (e.g. `token sourceName`) is SE016's finding.

    ## Why is this bad?
    *"The renderer should look for an output of this name as the computed
    value for the RenderVar."* (`pxr/usd/usdRender/schema.usda`). With `raw`
    the empty string reaches the renderer as-is, with `lpe` it is an empty
    expression, and hdPrman uses `sourceName` as the channel name of non-LPE
    vars (`third_party/renderman-26/plugin/hdPrman/renderParam.cpp`).

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "normal"
            {
                token dataType = "normal3f"
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
            def RenderVar "normal"
            {
                token dataType = "normal3f"
                string sourceName = "Nn"
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: only the author knows which output the var should read.
    """

    code = "VA001"
    name = "source-name-empty"
    severity = Severity.ERROR
    prim_types = (UsdRender.Var,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        if checked_value(prim, "sourceName", ctx) != "":
            return
        attr = prim.GetAttribute("sourceName")
        what = (
            "light path expression" if checked_value(prim, "sourceType", ctx) == "lpe" else "output"
        )
        yield Diagnostic(
            f"RenderVar {prim.GetPath()} has an empty sourceName: the renderer gets no {what} "
            'to compute; author the source it should read, e.g. string sourceName = "Ci"',
            at=attr if attr.IsAuthored() else prim,
        )


def _case_fix(attr: Usd.Attribute, correction: str | None, name: str) -> Fix | None:
    if correction is None:
        return None
    return Fix(f"set {name} to {correction!r}", True, set_value(attr.GetPath(), correction))


class SourceTypeNotAllowed(Rule):
    """A RenderVar's sourceType is not raw, primvar, lpe or intrinsic.

    ## What it does
    Reports an authored `sourceType` that is not one of the schema's
    `allowedTokens`: `raw`, `primvar`, `lpe`, `intrinsic`.

    ## Why is this bad?
    `allowedTokens = ["raw", "primvar", "lpe", "intrinsic"]`
    (`pxr/usd/usdRender/schema.usda`). Consumers branch on these exact tokens
    (hdPrman adds the `lpe:` and `primvars:` prefixes only for `lpe` and
    `primvar`), so any other value is treated like `raw` by some renderers and
    rejected by others.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "diffuse"
            {
                string sourceName = "diffuse"
                uniform token sourceType = "aov"
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
            def RenderVar "diffuse"
            {
                string sourceName = "diffuse"
                uniform token sourceType = "raw"
            }
        }
    }
    ```

    ## Fix safety
    Safe, conditional: a value that differs from an allowed token only in case
    (`LPE`) is corrected to it (`lpe`); otherwise there is no fix.
    """

    code = "VA002"
    name = "source-type-not-allowed"
    severity = Severity.ERROR
    fix_safety = "safe-conditional"
    prim_types = (UsdRender.Var,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("sourceType")
        value = authored_value(attr)
        if value is None:
            return
        allowed = allowed_tokens(prim, "sourceType")  # a schema lookup, only for a value
        if value in allowed:
            return
        correction = unique_case_match(value, allowed)
        advice = (
            f"did you mean {correction!r}?"
            if correction
            else "use raw for a renderer output name, lpe for a light path expression or "
            "primvar for a primvar"
        )
        yield Diagnostic(
            f"sourceType {value!r} of RenderVar {prim.GetPath()} is not one of "
            f"{', '.join(allowed)}; {advice}",
            at=attr,
            fix=_case_fix(attr, correction, "sourceType"),
        )


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
    fix_safety = "safe-conditional"
    prim_types = (UsdRender.Var,)

    @dataclass(frozen=True)
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
            fix = Fix("remove the leading 'lpe:'", True, set_value(attr.GetPath(), expression))
        yield Diagnostic(
            f"light path expression {source!r} of RenderVar {prim.GetPath()} "
            f"{' and '.join(parts)}; {' and '.join(advice)}",
            at=attr,
            fix=fix,
        )


#: Where the render prims live by convention; primvars there are not scene data.
RENDER_SCOPE = Sdf.Path("/Render")
PRIMVARS_PREFIX = "primvars:"


def _scene_primvar_names(stage: Usd.Stage) -> frozenset[str]:
    """Names of the primvars with authored values on any prim outside /Render,
    instance prototypes included (each prototype once)."""
    names: set[str] = set()
    roots = [stage.Traverse(), *(Usd.PrimRange(p) for p in stage.GetPrototypes())]
    for prims in roots:
        iterator = iter(prims)
        for prim in iterator:
            if prim.GetPath() == RENDER_SCOPE:
                iterator.PruneChildren()
                continue
            for primvar in UsdGeom.PrimvarsAPI(prim).GetPrimvarsWithAuthoredValues():
                names.add(str(primvar.GetPrimvarName()))
    return frozenset(names)


class PrimvarSourceNotFound(Rule):
    """A primvar-sourced RenderVar names a primvar no prim has.

    ## What it does
    For a RenderVar whose composed `sourceType` is `primvar`, takes
    `sourceName` (minus an optional `primvars:` prefix) and reports it when no
    prim outside `/Render` has a primvar of that name with an authored value.
    The scene's primvars are collected once per stage, and only when such a
    RenderVar exists; the rule is skipped on stages opened with a population
    mask, where the scene is not all there.

    ## Why is this bad?
    *"primvar": This source represents the name of a primvar. Some renderers
    may use this to ensure that the primvar is provided; other renderers may
    require that a suitable material network be provided, in which case this
    is simply an advisory setting.* (`pxr/usd/usdRender/schema.usda`). The
    setting can be advisory and primvars can arrive from payloads not loaded
    at lint time, hence info only.

    ## Example
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Mesh "card"
        {
            texCoord2f[] primvars:st = [(0, 0), (1, 0), (1, 1), (0, 1)] (
                interpolation = "vertex"
            )
        }
    }

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "uv"
            {
                token dataType = "float2"
                string sourceName = "uv"
                uniform token sourceType = "primvar"
            }
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Xform "World"
    {
        def Mesh "card"
        {
            texCoord2f[] primvars:st = [(0, 0), (1, 0), (1, 1), (0, 1)] (
                interpolation = "vertex"
            )
        }
    }

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "uv"
            {
                token dataType = "float2"
                string sourceName = "st"
                uniform token sourceType = "primvar"
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: the primvar may come from a payload or a material.
    """

    code = "VA004"
    name = "primvar-source-not-found"
    severity = Severity.INFO
    prim_types = (UsdRender.Var,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        if checked_value(prim, "sourceType", ctx) != "primvar":
            return
        source = checked_value(prim, "sourceName", ctx)
        if not source:
            return
        # The engine's partial stage holds only the render prims: ask for the
        # whole scene. A stage the user masked (catalog: --render-only) is skipped.
        ctx.require_full_stage()
        if not ctx.stage.GetPopulationMask().IncludesSubtree("/"):
            return
        name = source.removeprefix(PRIMVARS_PREFIX)
        names = ctx.memo(("VA004", "scene-primvars"), lambda: _scene_primvar_names(ctx.stage))
        if name in names:
            return
        yield Diagnostic(
            f"no prim outside {RENDER_SCOPE} has a primvar {name!r} (RenderVar {prim.GetPath()} "
            "reads it); check the spelling, or ignore this if the primvar comes from an "
            "unloaded payload or the material network",
            at=UsdRender.Var(prim).GetSourceNameAttr(),
        )


@cache
def _value_type_names() -> frozenset[str]:
    """Every type name Sdf knows, arrays and role names included."""
    names = (getattr(Sdf.ValueTypeNames, n) for n in dir(Sdf.ValueTypeNames))
    return frozenset(str(n) for n in names if isinstance(n, Sdf.ValueTypeName))


class DataTypeUnknown(Rule):
    """A RenderVar's dataType is not a USD value type name.

    ## What it does
    Reports an authored `dataType` (`uniform token`, fallback `color3f`, no
    `allowedTokens`) that `Sdf.ValueTypeNames.Find` does not know. The lookup is
    case-sensitive: `Float`, `rgb` and `vec3` fail.

    ## Why is this bad?
    *"The type of this channel, as a USD attribute type."*
    (`pxr/usd/usdRender/schema.usda`; `RenderVar.md`: *"as a USD attribute
    type (color3f, float, etc.)"*). Consumers map it to a pixel format (an
    HdFormat or a display-driver channel type); an unknown name has no
    mapping.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "color"
            {
                token dataType = "rgb"
                string sourceName = "Ci"
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
            def RenderVar "color"
            {
                token dataType = "color3f"
                string sourceName = "Ci"
            }
        }
    }
    ```

    ## Fix safety
    Safe, conditional: when exactly one type name matches ignoring case
    (`Float` -> `float`, `Color3F` -> `color3f`) the fix authors it; otherwise
    there is no fix.
    """

    code = "VA005"
    name = "data-type-unknown"
    severity = Severity.ERROR
    fix_safety = "safe-conditional"
    prim_types = (UsdRender.Var,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("dataType")
        value = authored_value(attr)
        if value is None or Sdf.ValueTypeNames.Find(value):
            return
        correction = unique_case_match(value, _value_type_names())
        advice = (
            f"did you mean {correction!r}?"
            if correction
            else "use a USD attribute type such as color3f, float, int or normal3f"
        )
        yield Diagnostic(
            f"dataType {value!r} of RenderVar {prim.GetPath()} is not a USD value type name; "
            + advice,
            at=attr,
            fix=_case_fix(attr, correction, "dataType"),
        )


#: Scalar types that cannot be a raster channel (catalog, VA006).
NON_PIXEL_SCALAR_TYPES = frozenset(
    {
        "string",
        "token",
        "asset",
        "opaque",
        "group",
        "pathExpression",
        "timecode",
        "duration",
        "frame4d",
        "bool",
        "matrix2d",
        "matrix3d",
        "matrix4d",
        "quatd",
        "quatf",
        "quath",
    }
)


class DataTypeNotPixelType(Rule):
    """A RenderVar's dataType cannot be stored per pixel.

    ## What it does
    Reports an authored `dataType` that is a valid type name (it passes VA005)
    but cannot be a per-pixel channel: an array type (`float[]`) or a
    non-numeric or non-vector scalar (`string, token, asset, opaque, group,
    pathExpression, timecode, duration, frame4d, bool`, matrices and
    quaternions).

    ## Why is this bad?
    A RenderVar is *"a quantity or 'channel' of computed data"* (RenderVar
    prim definition, usd-core 26.11) stored per pixel; image formats hold
    numeric scalars or small tuples (half, float, int, uint; 2 to 4
    components). Arrays and strings cannot be written to a raster channel.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "depth"
            {
                token dataType = "float[]"
                string sourceName = "z"
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
            def RenderVar "depth"
            {
                token dataType = "float"
                string sourceName = "z"
            }
        }
    }
    ```

    ## Fix safety
    Unsafe: an array of a numeric type `T[]` becomes `T`, which changes the
    channel the renderer writes; other types have no fix.
    """

    code = "VA006"
    name = "data-type-not-pixel-type"
    severity = Severity.WARNING
    fix_safety = "unsafe"
    prim_types = (UsdRender.Var,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("dataType")
        value = authored_value(attr)
        type_name = Sdf.ValueTypeNames.Find(value) if value else None
        if not type_name:
            return
        scalar = str(type_name.scalarType)
        numeric = scalar not in NON_PIXEL_SCALAR_TYPES
        if numeric and not type_name.isArray:
            return
        fix = None
        if numeric:
            problem, advice = "is an array type", f"use {scalar!r}"
            fix = Fix(f"set dataType to {scalar!r}", False, set_value(attr.GetPath(), scalar))
        else:
            problem = "is not a numeric scalar or vector type"
            advice = "use a numeric type such as float, int, float3 or color3f"
        yield Diagnostic(
            f"dataType {value!r} of RenderVar {prim.GetPath()} {problem} and cannot be a "
            f"per-pixel channel; {advice}",
            at=attr,
            fix=fix,
        )


#: Names of scalar quantities and the type the fix authors (None: ambiguous).
SCALAR_QUANTITY_TYPES = {
    "z": "float",
    "depth": "float",
    "a": "float",
    "alpha": "float",
    "coverage": "float",
    "id": "int",
    "primid": "int",
    "instanceid": "int",
    "elementid": "int",
    "mask": None,
}


class ScalarSourceDefaultColor3f(Rule):
    """A scalar-named RenderVar leaves dataType at the color3f fallback.

    ## What it does
    Reports a RenderVar with no authored `dataType` (so the fallback
    `color3f` applies) whose prim name or `sourceName` is, ignoring case, the
    name of a scalar quantity: `z, depth, a, alpha, id, primId, instanceId,
    elementId, coverage, mask`. A type-mismatched `dataType` opinion is
    SE016's finding.

    ## Why is this bad?
    The fallback is `color3f` (`uniform token dataType = "color3f"`,
    `pxr/usd/usdRender/schema.usda`), so an unauthored depth, alpha or id var
    is written as a 3-channel float colour: triple storage, and integer ids
    converted to float lose precision above 2^24. The official examples always
    author it: *"alpha" ... `token dataType = "float"`*, *"id" ... `token
    dataType = "int"`* (`RenderVar.md`).

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "depth"
            {
                string sourceName = "z"
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
            def RenderVar "depth"
            {
                token dataType = "float"
                string sourceName = "z"
            }
        }
    }
    ```

    ## Fix safety
    Safe, conditional: the fix authors `float` for `z/depth/a/alpha/coverage`
    and `int` for `id/primId/instanceId/elementId`, making explicit the type
    the author evidently meant; `mask`, or names implying different types,
    get no fix.
    """

    code = "VA007"
    name = "scalar-source-default-color3f"
    severity = Severity.WARNING
    fix_safety = "safe-conditional"
    prim_types = (UsdRender.Var,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        attr = prim.GetAttribute("dataType")
        if has_authored_value(attr) or mismatched_spec(attr) is not None:
            return
        candidates = (prim.GetName(), checked_value(prim, "sourceName", ctx) or "")
        matched = [n for n in candidates if n.lower() in SCALAR_QUANTITY_TYPES]
        if not matched:
            return
        types = {SCALAR_QUANTITY_TYPES[n.lower()] for n in matched}
        intended = types.pop() if len(types) == 1 else None
        fix = None
        if intended is not None:
            fix = Fix(f"author dataType = {intended!r}", True, set_value(attr.GetPath(), intended))
        advice = (
            f'author token dataType = "{intended}"'
            if intended
            else ('author the intended dataType, e.g. token dataType = "float"')
        )
        yield Diagnostic(
            f"RenderVar {prim.GetPath()} ({matched[0]!r}) is a scalar quantity but leaves "
            f'dataType at the fallback "color3f": it is written as a 3-channel colour; {advice}',
            at=prim,
            fix=fix,
        )


class AovNameCollision(Rule):
    """Two RenderVars of one product produce channels with the same name.

    ## What it does
    Reports two forwarded `orderedVars` targets of the same product that are
    RenderVar prims with the same prim name (e.g.
    `/Render/Vars/lighting/diffuse` and `/Render/Vars/albedo/diffuse`). With
    the option `aov-naming = "sourceName"` it also uses hdPrman's naming (the
    prim name for `lpe` vars, `sourceName` for the others) and reports two
    vars that collide under it.

    ## Why is this bad?
    *"The name of the RenderVar prim drives the name of the data variable
    that the renderer will produce."* (`pxr/usd/usdRender/schema.usda`, also
    `RenderVar.md`). Two vars named `diffuse` in one product produce two
    channels with the same name: one overwrites the other or the driver
    rejects the layout.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = [</Render/Vars/lighting/diffuse>, </Render/Vars/albedo/diffuse>]
        }

        def Scope "Vars"
        {
            def Scope "lighting"
            {
                def RenderVar "diffuse"
                {
                    string sourceName = "C<RD>[<L.>O]"
                    uniform token sourceType = "lpe"
                }
            }

            def Scope "albedo"
            {
                def RenderVar "diffuse"
                {
                    string sourceName = "albedo"
                }
            }
        }
    }
    ```

    ## Use instead
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def RenderProduct "Beauty"
        {
            token productName = "beauty.exr"
            rel orderedVars = [</Render/Vars/lighting/diffuse>, </Render/Vars/albedo/albedo>]
        }

        def Scope "Vars"
        {
            def Scope "lighting"
            {
                def RenderVar "diffuse"
                {
                    string sourceName = "C<RD>[<L.>O]"
                    uniform token sourceType = "lpe"
                }
            }

            def Scope "albedo"
            {
                def RenderVar "albedo"
                {
                    string sourceName = "albedo"
                }
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: renaming a prim changes a channel name that downstream
    comps rely on.

    ## Options
    `aov-naming` (`"primName"`, default, or `"sourceName"`): also check the
    hdPrman naming (catalog, Ambiguous semantics 7).
    """

    code = "VA008"
    name = "aov-name-collision"
    severity = Severity.ERROR
    prim_types = (UsdRender.Product,)

    @dataclass(frozen=True)
    class Options:
        aov_naming: AovNaming = "primName"

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        render_vars = product_render_vars(prim, ctx)
        namings: tuple[AovNaming, ...] = ("primName",)
        if self.options.aov_naming == "sourceName":
            namings = ("primName", "sourceName")
        reported: set[tuple[Sdf.Path, Sdf.Path]] = set()
        for naming in namings:
            owners: dict[str, Usd.Prim] = {}
            for var in render_vars:
                channel = channel_name(var, naming, ctx)
                first = owners.setdefault(channel, var)
                pair = (first.GetPath(), var.GetPath())
                if first.GetPath() == var.GetPath() or pair in reported:
                    continue
                reported.add(pair)
                how = (
                    "prim name"
                    if naming == "primName"
                    else "channel name under hdPrman's naming (sourceName for non-LPE vars)"
                )
                yield Diagnostic(
                    f"RenderVars {first.GetPath()} and {var.GetPath()} of {prim.GetPath()} share "
                    f"the {how} {channel!r}: the product gets two channels of that name and one "
                    "overwrites the other; rename one of them",
                    at=UsdRender.Product(prim).GetOrderedVarsRel(),
                )


class IntrinsicSourceUnimplemented(Rule):
    """A RenderVar uses the unimplemented sourceType intrinsic.

    ## What it does
    Reports a RenderVar whose composed `sourceType` is `intrinsic`.

    ## Why is this bad?
    *"intrinsic": This setting is currently unimplemented, but represents a
    future namespace for UsdRender to provide portable baseline RenderVars,
    such as camera depth, that may have varying implementations for each
    renderer.* (`pxr/usd/usdRender/schema.usda`). No renderer can be expected
    to honour it yet.

    ## Example
    ```usda
    #usda 1.0

    def Scope "Render"
    {
        def Scope "Vars"
        {
            def RenderVar "depth"
            {
                token dataType = "float"
                string sourceName = "depth"
                uniform token sourceType = "intrinsic"
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
            def RenderVar "depth"
            {
                token dataType = "float"
                string sourceName = "z"
                uniform token sourceType = "raw"
            }
        }
    }
    ```

    ## Fix safety
    No automatic fix: the renderer's own source name for the quantity is
    needed.
    """

    code = "VA009"
    name = "intrinsic-source-unimplemented"
    severity = Severity.INFO
    prim_types = (UsdRender.Var,)

    def check_prim(self, prim: Usd.Prim, ctx: Context) -> Iterator[Diagnostic]:
        if checked_value(prim, "sourceType", ctx) != "intrinsic":
            return
        yield Diagnostic(
            f'sourceType "intrinsic" of RenderVar {prim.GetPath()} is reserved and not yet '
            'implemented: no renderer is expected to produce it; use sourceType "raw" (or '
            '"lpe") with the renderer\'s own source name',
            at=UsdRender.Var(prim).GetSourceTypeAttr(),
        )


RULES = (
    SourceNameEmpty,
    SourceTypeNotAllowed,
    LpeMalformed,
    PrimvarSourceNotFound,
    DataTypeUnknown,
    DataTypeNotPixelType,
    ScalarSourceDefaultColor3f,
    AovNameCollision,
    IntrinsicSourceUnimplemented,
)
