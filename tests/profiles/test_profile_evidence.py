"""Every kind of evidence ``auto`` reads, for every renderer profile, decides
the profile wherever it sits in a scope: auto first asks, with one test per
kind for all renderers together, whether any prim of a scope holds any
(detect._Scan.plain), and builds the scopes only then, so a kind that test
missed would go unseen. The cases come from the profiles' own data: a new
namespace, API schema, scope, productType, camera or layer key is tested as
it is added, and a new field of Profile must be said to be evidence or not."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from pathlib import Path

import pytest
from pxr import Sdf, Usd

from usdrender_lint.api.cache import lint_cache
from usdrender_lint.api.resolve import prim_values
from usdrender_lint.engine import Linter
from usdrender_lint.profiles import GENERIC, PROFILES, Profiler, detect
from usdrender_lint.profiles.detect import Assignment
from usdrender_lint.profiles.model import Profile
from usdrender_lint.testing import all_rules

#: Profile fields whose values auto finds on the render prims of a scope
#: (detect._Scan.plain tests each kind; _Facts._found phrases it).
PRIM_EVIDENCE = {
    "namespaces",
    "api_schemas",
    "scopes",
    "product_types",
    "runtime_cameras",
    "camera_types",
}
#: Read from the root layer once per lint, whatever the prims hold.
LAYER_EVIDENCE = {"layer_data"}
#: What auto never reads: names, prose, sources, rule changes and what the
#: rules accept.
NOT_EVIDENCE = {
    "name",
    "description",
    "family",
    "evidence_sources",
    "changes",
    "prim_types",
    "var_outputs",
    "behaviours",
}


def test_every_profile_field_is_said_to_be_evidence_or_not() -> None:
    fields = {f.name for f in dataclasses.fields(Profile)}
    assert fields == PRIM_EVIDENCE | LAYER_EVIDENCE | NOT_EVIDENCE


def _value(pattern: str) -> str:
    """A name that an Accepted or API schema pattern matches."""
    assert "[" not in pattern, "a pattern with a character class needs a case of its own"
    return pattern.replace("*", "X").replace("?", "X")


#: The render prims every case builds on: settings, a product, a var, a camera.
BASE = {
    "/Cam": ('def Camera "Cam"', []),
    "/Render": ('def Scope "Render"', []),
    "/Render/S": (
        'def RenderSettings "S"',
        ["rel camera = </Cam>", "rel products = </Render/P>"],
    ),
    "/Render/P": ('def RenderProduct "P"', ["rel orderedVars = </Render/V>"]),
    "/Render/V": ('def RenderVar "V"', ['string sourceName = "Ci"']),
}


def _usda(prims: dict[str, tuple[str, list[str]]], header: str = "") -> str:
    """A usda text of ``prims`` (path -> (def line, property lines)); parents first."""
    children: dict[str, list[str]] = {}
    for path in prims:
        children.setdefault(path.rsplit("/", 1)[0] or "/", []).append(path)

    def write(path: str, depth: int) -> list[str]:
        head, properties = prims[path]
        pad = "    " * depth
        lines = [pad + head, pad + "{"]
        lines += [pad + "    " + p for p in properties]
        for child in children.get(path, []):
            lines += write(child, depth + 1)
        return [*lines, pad + "}"]

    text = [f"#usda 1.0\n{header}"]
    for root in children.get("/", []):
        text += write(root, 0)
    return "\n".join(text) + "\n"


def _cases(profile: Profile) -> Iterator[tuple[str, str]]:
    """(what, usda) for each piece of evidence of ``profile``; the settings
    prim is /Render/S, or S under a renderer's scope."""
    for namespace in profile.namespaces:
        for where in ("/Render/S", "/Render/P", "/Render/V"):
            prims = dict(BASE)
            head, properties = prims[where]
            prims[where] = (head, [*properties, f"int {namespace}evidence = 1"])
            yield f"property {namespace}* on {where}", _usda(prims)
    for pattern in profile.api_schemas:
        for where in ("/Render/S", "/Render/P", "/Render/V"):
            prims = dict(BASE)
            head, properties = prims[where]
            applied = f'{head} (\n    prepend apiSchemas = ["{_value(pattern)}"]\n)'
            prims[where] = (applied, properties)
            yield f"API schema {pattern} on {where}", _usda(prims)
    for scope in profile.scopes:
        # The settings prim under the scope, its ancestors typeless.
        root = scope.rstrip("/")
        prims = {p: v for p, v in BASE.items() if p != "/Render/S"}
        parts = root.strip("/").split("/")
        for depth in range(1, len(parts) + 1):
            path = "/" + "/".join(parts[:depth])
            prims.setdefault(path, (f'def "{parts[depth - 1]}"', []))
        prims[root + "/S"] = ('def RenderSettings "S"', BASE["/Render/S"][1])
        yield f"the scope {scope}", _usda(prims)
    for accepted in profile.product_types:
        prims = dict(BASE)
        token = _value(accepted.name)
        prims["/Render/P"] = (
            'def RenderProduct "P"',
            [*BASE["/Render/P"][1], f'uniform token productType = "{token}"'],
        )
        yield f"productType {token}", _usda(prims)
    for accepted in profile.runtime_cameras:
        path = _value(accepted.name)
        for where in ("/Render/S", "/Render/P"):
            prims = dict(BASE)
            head, properties = prims[where]
            others = [p for p in properties if not p.startswith("rel camera")]
            prims[where] = (head, [*others, f"rel camera = <{path}>"])
            yield f"camera <{path}> of {where}", _usda(prims)
    for accepted in profile.camera_types:
        prims = dict(BASE)
        prims["/Cam"] = (f'def {_value(accepted.name)} "Cam"', [])
        yield f"a camera of type {accepted.name}", _usda(prims)
    for accepted in profile.layer_data:
        *dictionaries, key = _value(accepted.name).split(":")
        data = f'string {key} = "evidence"'
        for name in reversed(dictionaries):
            data = f"dictionary {name} = {{\n{data}\n}}"
        yield (
            f"layer data {accepted.name}",
            _usda(dict(BASE), f"(\n    customLayerData = {{\n{data}\n}}\n)\n"),
        )


CASES = [
    pytest.param(name, usda, id=f"{name}: {what}")
    for name, profile in PROFILES.items()
    if profile is not GENERIC
    for what, usda in _cases(profile)
]


def test_every_renderer_has_evidence() -> None:
    names = {p.values[0] for p in CASES}
    assert names == set(PROFILES) - {GENERIC.name}


def _assignment(tmp_path: Path, usda: str) -> Assignment:
    path = tmp_path / "shot.usda"
    path.write_text(usda, encoding="utf-8")
    decided: list[Assignment] = []
    profiler = Profiler()

    def deciding(ctx):
        decided.append(profiler(ctx))
        return decided[-1]

    result = Linter(all_rules(), raise_errors=True, profiler=deciding).lint_path(str(path))
    assert result.status == "linted", result.error
    return decided[0]


def _settings_paths(usda: str) -> list[str]:
    stage = Usd.Stage.CreateInMemory()
    stage.GetRootLayer().ImportFromString(usda)
    return [str(p.GetPath()) for p in stage.Traverse() if p.GetTypeName() == "RenderSettings"]


@pytest.mark.parametrize(("name", "usda"), CASES)
def test_each_piece_of_evidence_picks_its_renderer(tmp_path: Path, name: str, usda: str) -> None:
    assignment = _assignment(tmp_path, usda)
    assert assignment.stage.name == name, assignment.stage.reason
    settings = next(p for p in _settings_paths(usda) if p.endswith("/S"))
    assert assignment.for_scope(Sdf.Path(settings)).name == name


def test_without_evidence_every_scope_is_the_stages(tmp_path: Path) -> None:
    assignment = _assignment(tmp_path, _usda(BASE))
    assert assignment.stage.name == "generic"
    assert assignment.stage.reason.startswith("auto: no renderer's")


def test_every_namespace_ends_with_a_colon() -> None:
    """The quick test looks for a ":" in a prim's names before matching
    every renderer's namespaces (detect._Scan.plain)."""
    for profile in PROFILES.values():
        for namespace in profile.namespaces:
            assert namespace.endswith(":"), (profile.name, namespace)


def _with(where: str, *lines: str, head: str | None = None) -> str:
    prims = dict(BASE)
    old_head, properties = prims[where]
    prims[where] = (head or old_head, [*properties, *lines])
    return _usda(prims)


#: Stages whose prims share what the quick test remembers per lint: a camera
#: target of both the settings and a product, a product that authors no
#: productType (its definition's answer) before one that does, vars that
#: several products target.
SHARING_PRIMS = [
    _usda(
        {
            **BASE,
            "/Cam": ('def OmniLidar "Cam"', []),
            "/Render/P": ('def RenderProduct "P"', ["rel camera = </Cam>"]),
        }
    ),
    _usda(
        {
            **BASE,
            "/Render/S": (
                'def RenderSettings "S"',
                ["rel camera = </Cam>", "rel products = [</Render/P>, </Render/Q>]"],
            ),
            "/Render/Q": (
                'def RenderProduct "Q"',
                ['uniform token productType = "arnold"', "rel orderedVars = </Render/V>"],
            ),
            "/Render/W": ('def RenderVar "W"', ["int karma:evidence = 1"]),
            "/Render/R": (
                'def RenderProduct "R"',
                ["rel orderedVars = [</Render/V>, </Render/W>]"],
            ),
        }
    ),
    _with("/Render/V", "int arnold:evidence = 1"),
    _with("/Render/P", "rel camera = </OmniverseKit_Persp>"),
]


@pytest.mark.parametrize("usda", [_usda(BASE), *SHARING_PRIMS, *(p.values[1] for p in CASES)])
def test_the_quick_test_agrees_with_the_full_scan(usda: str) -> None:
    """``plain`` (one test per kind of evidence, answers shared between prims)
    says a prim holds no evidence exactly when the full scan of each renderer
    finds none on it, whatever prims were asked before it."""
    stage = Usd.Stage.CreateInMemory()
    stage.GetRootLayer().ImportFromString(usda)
    with lint_cache():
        prims = list(stage.Traverse())
        quick, full = detect._Scan(stage), detect._Scan(stage)
        full.plain = lambda values, kind: False  # type: ignore[method-assign]  # scan them all
        plain = [quick.plain(prim_values(p), detect._kind(p)) for p in prims]
        found = [full.facts(p).evidence for p in prims]
    assert plain == [not f for f in found]
    # Every case but the plain one and the layer's data holds evidence on a prim.
    assert not all(plain) or usda == _usda(BASE) or "customLayerData" in usda
