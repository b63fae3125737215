"""The fast path (a stage composed only around the render prims) gives exactly
the findings of a full composition, and falls back to it where a shortcut
could miss something. Correctness only: timing is the benchmark's job."""

from __future__ import annotations

import json
import signal
from collections.abc import Iterator
from pathlib import Path

import pytest
from bench_support import load_script
from pxr import Sdf, UsdRender

from usdrender_lint.api import Context, Diagnostic, Rule, Severity
from usdrender_lint.engine import Linter, layer_words
from usdrender_lint.engine import partial as fastpath
from usdrender_lint.testing import all_rules

pytestmark = pytest.mark.heavy(seconds=14)

TESTS = Path(__file__).parents[1]
REPO = TESTS.parent
#: Every layer of every rule fixture folder (supporting layers too) and the
#: examples, discovered so the check grows with the rules.
LAYERS = sorted([*(TESTS / "rules").rglob("*.usd*"), *(REPO / "examples").rglob("*.usd*")])


generate = load_script("generate")


@pytest.fixture(scope="module")
def linters() -> Iterator[tuple[Linter, Linter]]:
    rules = all_rules()
    # Most fixtures are single layers, which the engine composes fully for
    # speed: take the fast path anyway so that it is what gets compared.
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(fastpath, "FLAT_STAGES_COMPOSE_FULLY", False)
        yield Linter(rules, full_composition=False), Linter(rules, full_composition=True)


def test_flat_stages_compose_fully(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setattr(fastpath, "FLAT_STAGES_COMPOSE_FULLY", True)
    root = _write(tmp_path, {"shot.usda": RENDER_ASSET})
    opened = fastpath.open_partial(str(root), Linter(all_rules())._dispatch.wants)
    assert opened.stage is None and "root layer stack" in opened.reason


def test_text_without_asset_paths_is_flat_before_usd_reads_it(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setattr(fastpath, "FLAT_STAGES_COMPOSE_FULLY", True)
    root = _write(tmp_path, {"shot.usda": RENDER_ASSET})
    opened = fastpath.open_partial(str(root), Linter(all_rules())._dispatch.wants)
    assert opened.stage is None and "root layer stack" in opened.reason
    # Decided from the text alone: USD did not read the layer (the engine will, once).
    assert opened.layers == [] and Sdf.Layer.Find(str(root)) is None


@pytest.mark.parametrize(
    "text",
    [
        "#usda 1.0\n(\n    subLayers = [@lighting.usda@]\n)\n",
        '#usda 1.0\ndef "Set" (\n    references = @lighting.usda@\n)\n{\n}\n',
        '#usda 1.0\ndef "Set" (\n    payload = @lighting.usda@\n)\n{\n}\n',
        # Past the first read of the text.
        "#usda 1.0\n"
        + "# padding\n" * 20_000
        + 'def "Set" (\n    references = @lighting.usda@\n)\n{\n}\n',
    ],
    ids=["sublayer", "reference", "payload", "late-reference"],
)
def test_text_with_an_arc_to_a_layer_is_not_taken_for_flat(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, text: str
) -> None:
    monkeypatch.setattr(fastpath, "FLAT_STAGES_COMPOSE_FULLY", True)
    light = '#usda 1.0\ndef "Light"\n{\n}\n'
    root = _write(tmp_path, {"shot.usda": text, "lighting.usda": light})
    assert Sdf.Layer.FindOrOpen(str(root)).GetCompositionAssetDependencies()
    assert not layer_words.without_external_arcs(str(root))
    opened = fastpath.open_partial(str(root), Linter(all_rules())._dispatch.wants)
    assert opened.layers, "the layers must be asked for their dependencies"


def test_an_asset_valued_attribute_alone_leaves_the_stage_flat(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setattr(fastpath, "FLAT_STAGES_COMPOSE_FULLY", True)
    text = RENDER_ASSET.replace("(0, 1080)", "(0, 1080)\n        asset note = @notes.txt@")
    root = _write(tmp_path, {"shot.usda": text})
    opened = fastpath.open_partial(str(root), Linter(all_rules())._dispatch.wants)
    assert opened.stage is None and "root layer stack" in opened.reason
    assert opened.layers  # the text check could not tell; the layer said so


def _wants(linter: Linter):
    return linter._dispatch.wants


def _partial_stage(linters: tuple[Linter, Linter], path: Path):
    """The fast path's stage for ``path``, which must take the fast path."""
    opened = fastpath.open_partial(str(path), _wants(linters[0]))
    assert opened.stage is not None, opened.reason
    return opened.stage


def _falls_back(linters: tuple[Linter, Linter], path: Path) -> bool:
    return fastpath.open_partial(str(path), _wants(linters[0])).stage is None


def _assert_same(linters: tuple[Linter, Linter], path: Path) -> None:
    fast, full = linters
    got, expected = fast.lint_path(str(path)), full.lint_path(str(path))
    assert got == expected, f"{path}: fast path findings differ from full composition"


@pytest.mark.parametrize("path", LAYERS, ids=lambda p: str(p.relative_to(REPO)))
def test_fixture_findings_identical(linters: tuple[Linter, Linter], path: Path) -> None:
    _assert_same(linters, path)


def test_corpus_findings_identical(linters: tuple[Linter, Linter], shared_dir: Path) -> None:
    # Real public USD files (mostly flat, so the fast path is forced).
    files = sorted((shared_dir / "corpus" / "files").rglob("*.usd*"))
    assert files
    fast, full = linters
    differ = [str(f) for f in files if fast.lint_path(str(f)) != full.lint_path(str(f))]
    assert not differ, f"fast path findings differ on {differ}"


def test_most_fixtures_take_the_fast_path(linters: tuple[Linter, Linter]) -> None:
    # Equality above would hold trivially if the fast path always gave up.
    partial = [p for p in LAYERS if not _falls_back(linters, p)]
    assert len(partial) >= 0.8 * len(LAYERS)


# -- generated shots --------------------------------------------------------------------


@pytest.fixture(scope="module", params=generate.FORMATS)
def shot(request, tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp(f"shot_{request.param}")
    return generate.generate_shot(folder, prims=3000, fmt=request.param)


def _pairs(result) -> set[tuple[str, str]]:
    return {(f.code, f.location.path) for f in result.findings}


def _assert_finds(linters: tuple[Linter, Linter], path: Path, code: str, where: str) -> None:
    """Both modes give the same findings, ``code`` at ``where`` among them."""
    _assert_same(linters, path)
    assert (code, where) in _pairs(linters[0].lint_path(str(path)))


def test_generated_shot_is_partly_composed_and_exact(
    linters: tuple[Linter, Linter], shot: Path
) -> None:
    stage = _partial_stage(linters, shot)
    # The render prims and what they target are composed; the set is not.
    assert stage.GetPrimAtPath("/Render/Settings").IsA(UsdRender.Settings)
    assert stage.GetPrimAtPath("/World/cams/shotCam")
    assert stage.GetPrimAtPath("/World/lights/light_0000")  # a pass includes it
    assert not stage.GetPrimAtPath("/World/set/inst_000000")
    _assert_same(linters, shot)


def test_generated_shot_injected_defects_are_found(
    linters: tuple[Linter, Linter], shot: Path
) -> None:
    expected = json.loads((shot.parent / generate.EXPECTED_FILE).read_text())[shot.name]
    assert expected
    found = _pairs(linters[0].lint_path(str(shot)))
    assert {(e["code"], e["path"]) for e in expected} <= found


def test_many_small_shots_identical(linters: tuple[Linter, Linter], tmp_path: Path) -> None:
    files = generate.generate_many(tmp_path, count=3, prims=60, defect_every=2)
    expected = json.loads((tmp_path / generate.EXPECTED_FILE).read_text())
    for path in files:
        _assert_same(linters, path)
        pairs = {(e["code"], e["path"]) for e in expected[path.name]}
        assert pairs <= _pairs(linters[0].lint_path(str(path)))
    assert expected[files[0].name] and not expected[files[1].name]


# -- where the fast path must give up or follow arcs ---------------------------------------

RENDER_ASSET = """#usda 1.0
(
    defaultPrim = "Render"
)

def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform int2 resolution = (0, 1080)
    }
}
"""


def _write(folder: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8")
    return folder / next(iter(files))


def test_render_prims_from_a_reference_fall_back(
    linters: tuple[Linter, Linter], tmp_path: Path
) -> None:
    root = _write(
        tmp_path,
        {
            "shot.usda": '#usda 1.0\ndef Xform "World"\n{\n    def "facility" '
            "(references = @./render.usda@)\n    {\n    }\n}\n",
            "render.usda": RENDER_ASSET,
        },
    )
    assert _falls_back(linters, root)
    _assert_finds(linters, root, "SE001", "/World/facility/Settings.resolution")


def test_render_prims_from_a_payload_fall_back(
    linters: tuple[Linter, Linter], tmp_path: Path
) -> None:
    root = _write(
        tmp_path,
        {
            "shot.usda": '#usda 1.0\ndef "Render" (payload = @./render.usda@)\n{\n}\n',
            "render.usda": RENDER_ASSET,
        },
    )
    assert _falls_back(linters, root)
    _assert_same(linters, root)


def test_internal_inherits_are_followed(linters: tuple[Linter, Linter], tmp_path: Path) -> None:
    # The settings type comes from a class in the same layer: the mask maps it.
    root = _write(
        tmp_path,
        {
            "shot.usda": """#usda 1.0
class RenderSettings "_settings"
{
    uniform int2 resolution = (0, 1080)
}

def Xform "World"
{
    def "settings" (inherits = </_settings>)
    {
    }
}
"""
        },
    )
    stage = _partial_stage(linters, root)
    assert stage.GetPrimAtPath("/World/settings").IsA(UsdRender.Settings)
    _assert_finds(linters, root, "SE001", "/World/settings.resolution")


def test_class_inherited_from_an_asset_falls_back(
    linters: tuple[Linter, Linter], tmp_path: Path
) -> None:
    # Implied inheritance: the asset's prim inherits </_settings>, which the
    # shot defines as RenderSettings, so /World/asset/cfg is one too.
    root = _write(
        tmp_path,
        {
            "shot.usda": """#usda 1.0
class RenderSettings "_settings"
{
    uniform int2 resolution = (0, 1080)
}

def Xform "World"
{
    def "asset" (references = @./asset.usda@)
    {
    }
}
""",
            "asset.usda": '#usda 1.0\n(\n    defaultPrim = "asset"\n)\n'
            'def "asset"\n{\n    def "cfg" (inherits = </_settings>)\n    {\n    }\n}\n',
        },
    )
    assert _falls_back(linters, root)
    _assert_finds(linters, root, "SE001", "/World/asset/cfg.resolution")


def test_expression_references_are_composed(linters: tuple[Linter, Linter], tmp_path: Path) -> None:
    root = _write(
        tmp_path,
        {
            "shot.usda": """#usda 1.0
def Xform "World"
{
    def Xform "sets" (
        prepend apiSchemas = ["CollectionAPI:hero"]
    )
    {
        uniform token collection:hero:expansionRule = "expandPrims"
    }
}

def Scope "Render"
{
    def RenderPass "beauty" (
        prepend apiSchemas = ["CollectionAPI:renderVisibility"]
    )
    {
        uniform bool collection:renderVisibility:includeRoot = 0
        pathExpression collection:renderVisibility:membershipExpression = "%/World/sets:hero"
    }
}
"""
        },
    )
    stage = _partial_stage(linters, root)
    assert stage.GetPrimAtPath("/World/sets")
    _assert_same(linters, root)


class _CountsPrims(Rule):
    """Counts every prim on the stage (a rule that walks the whole scene).

    ## What it does
    Test only.
    """

    code = "ZZ901"
    name = "counts-prims"
    severity = Severity.INFO

    def check_stage(self, ctx: Context) -> Iterator[Diagnostic]:
        ctx.require_full_stage()
        yield Diagnostic(message=f"{sum(1 for _ in ctx.stage.Traverse())} prims")


def test_a_rule_can_require_the_full_stage(tmp_path: Path) -> None:
    root = generate.generate_shot(tmp_path, prims=1000, fmt="usda", defects=False)
    counts = {
        full: [
            f.message
            for f in Linter([_CountsPrims()], full_composition=full).lint_path(str(root)).findings
        ]
        for full in (False, True)
    }
    assert counts[False] == counts[True]
    assert int(counts[True][0].split()[0]) > 900


def test_full_composition_switch_never_takes_the_fast_path(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    root = _write(tmp_path, {"shot.usda": RENDER_ASSET})

    def refuse(*_args, **_kwargs):
        raise AssertionError("fast path used")

    monkeypatch.setattr(fastpath, "open_partial", refuse)
    rules = all_rules()
    assert Linter(rules, full_composition=True, raise_errors=True).lint_path(str(root)).findings
    assert not Linter(rules).full_composition  # the built-in rules all opt in


def test_payloads_load_only_inside_the_mask(linters: tuple[Linter, Linter], tmp_path: Path) -> None:
    # The camera sits behind a payload: it is loaded because a settings targets it.
    root = _write(
        tmp_path,
        {
            "shot.usda": """#usda 1.0
def Xform "World"
{
    def "cams" (payload = @./cams.usda@)
    {
    }
    def "props" (payload = @./cams.usda@)
    {
    }
}

def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel camera = </World/cams/main/rig>
    }
}
""",
            "cams.usda": """#usda 1.0
(
    defaultPrim = "c"
)

def "c"
{
    def Xform "main"
    {
        def Xform "rig"
        {
            def Camera "cam"
            {
            }
        }
    }
}
""",
        },
    )
    stage = _partial_stage(linters, root)
    assert stage.GetPrimAtPath("/World/cams/main/rig/cam")
    assert not stage.GetPrimAtPath("/World/props/main")
    _assert_finds(linters, root, "CA004", "/Render/Settings.camera")


def test_suppressions_outside_the_render_scope_are_composed(
    linters: tuple[Linter, Linter], tmp_path: Path
) -> None:
    # An unused suppression on a geometry prim is still reported.
    root = _write(
        tmp_path,
        {
            "shot.usda": """#usda 1.0
def Xform "World"
{
    def Mesh "prop" (
        customData = {
            dictionary usdrender_lint = {
                string[] ignore = ["SE003"]
            }
        }
    )
    {
    }
}
"""
        },
    )
    assert _partial_stage(linters, root).GetPrimAtPath("/World/prop")
    _assert_same(linters, root)


def test_unreadable_dependency_falls_back(linters: tuple[Linter, Linter], tmp_path: Path) -> None:
    root = _write(
        tmp_path,
        {
            "shot.usda": '#usda 1.0\ndef "World" (references = @./broken.usda@)\n{\n}\n'
            'def Scope "Render"\n{\n    def RenderSettings "S"\n    {\n    }\n}\n',
            "broken.usda": '#usda 1.0\ndef Xform "X" (\n',
        },
    )
    assert _falls_back(linters, root)
    _assert_same(linters, root)


@pytest.mark.parametrize(
    "asset",
    [
        '#usda 1.0\n(\n    subLayers = [@./gone.usda@]\n)\ndef "A"\n{\n}\n',
        '#usda 1.0\n(\n    subLayers = [@./loop.usda@]\n)\ndef "A"\n{\n}\n',
    ],
    ids=["missing-sublayer", "sublayer-cycle"],
)
def test_layer_stack_errors_of_a_referenced_layer_fall_back(
    linters: tuple[Linter, Linter], tmp_path: Path, asset: str
) -> None:
    # USD reports them at </> (ST002 on every stage), but only when it composes
    # the prim that references the layer, which the mask leaves out.
    root = _write(
        tmp_path,
        {
            "shot.usda": '#usda 1.0\ndef "World" (references = @./asset.usda@)\n{\n}\n'
            'def Scope "Render"\n{\n    def RenderSettings "S"\n    {\n    }\n}\n',
            "asset.usda": asset,
            "loop.usda": "#usda 1.0\n(\n    subLayers = [@./asset.usda@]\n)\n",
        },
    )
    assert _falls_back(linters, root)
    _assert_finds(linters, root, "ST002", None)


_EXPLICIT_CLIPS = (
    "            asset[] assetPaths = [@./anim.1.usda@]\n"
    "            double2[] active = [(0, 0)]\n"
    "            double2[] times = [(0, 0), (1, 1)]\n"
)
_TEMPLATE_CLIPS = (
    '            string templateAssetPath = "./anim.#.usda"\n'
    "            double templateStartTime = 1\n"
    "            double templateEndTime = 1\n"
    "            double templateStride = 1\n"
)


@pytest.mark.parametrize("clip_set", [_EXPLICIT_CLIPS, _TEMPLATE_CLIPS], ids=["paths", "template"])
def test_a_clip_layer_authoring_the_settings_path_falls_back(
    linters: tuple[Linter, Linter], tmp_path: Path, clip_set: str
) -> None:
    # Value clip layers are used layers (ST007 reads their metadata), but only
    # those of the prims the stage composes: /Anim is outside the mask.
    clips = (
        "    clips = {\n        dictionary default = {\n"
        f'{clip_set}            string primPath = "/Anim"\n        }}\n    }}\n'
    )
    root = _write(
        tmp_path,
        {
            "shot.usda": '#usda 1.0\n(\n    renderSettingsPrimPath = "/Render/S"\n)\n'
            'def "World" (references = @./asset.usda@)\n{\n}\n'
            f'def Xform "Anim" (\n{clips})\n{{\n}}\n'
            'def Scope "Render"\n{\n    def RenderSettings "S"\n    {\n    }\n}\n',
            "asset.usda": '#usda 1.0\ndef "A"\n{\n}\n',
            "anim.1.usda": '#usda 1.0\n(\n    renderSettingsPrimPath = "/Render/Old"\n)\n'
            'over "Anim"\n{\n    double x.timeSamples = {\n        0: 1,\n    }\n}\n',
        },
    )
    assert _falls_back(linters, root)
    _assert_finds(linters, root, "ST007", None)


def test_arcs_that_nest_copies_without_end_fall_back_at_once(
    linters: tuple[Linter, Linter], tmp_path: Path
) -> None:
    # Each of /World/A, /World/B, /World/C references its own ancestor (a
    # cycle USD reports and does not compose): following the arcs would copy
    # the product into copies of copies, three times more paths each round.
    nested = "".join(
        f'    def "{name}" (references = </World>)\n    {{\n    }}\n' for name in "ABC"
    )
    root = _write(
        tmp_path,
        {
            "shot.usda": '#usda 1.0\ndef "Set" (references = @./set.usda@)\n{\n}\n'
            'def Xform "World"\n{\n    def RenderProduct "P"\n    {\n    }\n'
            f"{nested}}}\n",
            "set.usda": '#usda 1.0\ndef "A"\n{\n}\n',
        },
    )

    def expire(signum: int, frame: object) -> None:
        raise TimeoutError("the fast path did not give up")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(30)
    try:
        assert _falls_back(linters, root)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    _assert_same(linters, root)


def test_variant_specs_are_found(linters: tuple[Linter, Linter], tmp_path: Path) -> None:
    root = _write(
        tmp_path,
        {
            "shot.usda": """#usda 1.0
def Scope "Shot" (
    variants = { string look = "final" }
    prepend variantSets = "look"
)
{
    variantSet "look" = {
        "final" {
            def RenderSettings "Settings"
            {
                uniform int2 resolution = (0, 1080)
            }
        }
    }
}
"""
        },
    )
    stage = _partial_stage(linters, root)
    assert stage.GetPopulationMask().Includes(Sdf.Path("/Shot/Settings"))
    _assert_finds(linters, root, "SE001", "/Shot/Settings.resolution")


def test_cli_full_composition_flag(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    from click.testing import CliRunner

    from usdrender_lint.cli import cli

    root = generate.generate_shot(tmp_path, prims=500, fmt="usda")

    def refuse(*_args, **_kwargs):
        raise AssertionError("fast path used")

    monkeypatch.setattr(fastpath, "open_partial", refuse)
    argv = ["check", "--isolated", "--jobs", "1", "--timeout", "0", "--format", "json"]
    result = CliRunner().invoke(cli, [*argv, "--full-composition", str(root)])
    assert result.exit_code == 1, result.output
    codes = {f["code"] for f in json.loads(result.stdout)["files"][0]["findings"]}
    assert {"SE003", "PR004", "CA004", "CA003"} <= codes


def test_scanning_more_than_a_full_composition_composes_is_not_done(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, shot: Path
) -> None:
    monkeypatch.setattr(fastpath, "MIN_SCAN", 100)
    wants = Linter(all_rules())._dispatch.wants
    # Many unique prims and one reference: composing them is cheaper than scanning.
    prims = "\n".join(f'def Xform "p{i}"\n{{\n    double size = {i}\n}}' for i in range(300))
    root = _write(
        tmp_path,
        {
            "shot.usda": f'#usda 1.0\ndef "asset" (references = @./asset.usda@)\n{{\n}}\n{prims}\n',
            "asset.usda": '#usda 1.0\n(\n    defaultPrim = "a"\n)\ndef Xform "a"\n{\n}\n',
        },
    )
    opened = fastpath.open_partial(str(root), wants)
    assert opened.stage is None and "cheaper" in opened.reason
    # The generated shot references each asset many times: the fast path pays.
    assert fastpath.open_partial(str(shot), wants).stage is not None


class _ReadsTheSet(Rule):
    """Reports when the set brought in by a reference has no Mesh (test-only).

    Written as the plugin guide shows a third-party rule: on RenderSettings, it reads
    a prim outside the render prims, their targets and ancestors.

    ## What it does
    ## Why is this bad?
    ## Example
    ## Use instead
    ## Fix safety
    """

    code = "ZZ950"
    name = "reads-the-set"
    severity = Severity.WARNING
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim, ctx: Context):
        mesh = ctx.stage.GetPrimAtPath("/World/set/ground")
        if not mesh:
            yield Diagnostic(message="the set's ground is missing", at=prim)
        else:
            yield Diagnostic(message=f"the set's ground is a {mesh.GetTypeName()}", at=prim)


SHOT_WITH_A_SET = {
    "shot.usda": '#usda 1.0\ndef Xform "World"\n{\n    def "set" (references = @./set.usda@)\n'
    "    {\n    }\n}\n"
    'def Scope "Render"\n{\n    def RenderSettings "Settings"\n    {\n    }\n}\n',
    "set.usda": '#usda 1.0\n(\n    defaultPrim = "set"\n)\ndef Xform "set"\n{\n'
    '    def Mesh "ground"\n    {\n    }\n}\n',
}


def test_a_rule_that_does_not_opt_in_sees_the_whole_stage(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setattr(fastpath, "FLAT_STAGES_COMPOSE_FULLY", False)
    root = str(_write(tmp_path, SHOT_WITH_A_SET))
    plugin = Linter([_ReadsTheSet(), *all_rules()], raise_errors=True)
    assert plugin.full_composition  # one rule without the opt-in decides
    messages = {f.message for f in plugin.lint_path(root).findings if f.code == "ZZ950"}
    assert messages == {"the set's ground is a Mesh"}
    # The same rule claiming the opt-in it does not honour is what the mask
    # would hide: the engine believes the declaration.
    monkeypatch.setattr(_ReadsTheSet, "partial_composition", True)
    masked = Linter([_ReadsTheSet()], raise_errors=True)
    assert not masked.full_composition
    messages = {f.message for f in masked.lint_path(root).findings if f.code == "ZZ950"}
    assert messages == {"the set's ground is missing"}


def test_every_built_in_rule_opts_in_to_partial_composition() -> None:
    assert all(type(rule).partial_composition for rule in all_rules())
    assert not Linter(all_rules()).full_composition


#: Every way a layer reaches another: a sublayer, a reference (prepended, in a
#: variant), a payload, a sublayer of a referenced layer, one arc named twice,
#: a missing layer; and a deleted reference, which composes nothing.
REACHING = {
    "shot.usda": "#usda 1.0\n(\n    subLayers = [@./layout.usda@]\n)\n"
    'def Xform "World"\n{\n'
    '    def "a" (prepend references = @./a.usda@)\n    {\n    }\n'
    '    def "again" (prepend references = @./a.usda@)\n    {\n    }\n'
    '    def "v" (\n        variants = {\n            string look = "on"\n        }\n'
    '        prepend variantSets = "look"\n    )\n    {\n'
    '        variantSet "look" = {\n'
    '            "on" (prepend payload = @./p.usda@) {\n            }\n'
    "        }\n    }\n"
    '    over "gone" (delete references = @./deleted.usda@)\n    {\n    }\n'
    '    def "lost" (prepend references = @./missing.usda@)\n    {\n    }\n}\n',
    "layout.usda": '#usda 1.0\ndef Xform "set" (prepend payload = @./set.usda@)\n{\n}\n',
    "a.usda": '#usda 1.0\n(\n    defaultPrim = "a"\n    subLayers = [@./a_base.usda@]\n)\n'
    'def Xform "a"\n{\n}\n',
    "a_base.usda": '#usda 1.0\ndef Xform "a"\n{\n    double size = 1\n}\n',
    "p.usda": '#usda 1.0\n(\n    defaultPrim = "p"\n)\ndef Xform "p"\n{\n}\n',
    "set.usda": '#usda 1.0\n(\n    defaultPrim = "set"\n)\ndef Xform "set"\n{\n}\n',
    "deleted.usda": '#usda 1.0\n(\n    defaultPrim = "d"\n)\ndef Xform "d"\n{\n}\n',
}


def test_the_layers_reached_are_those_a_full_composition_uses(tmp_path: Path) -> None:
    """The fast path reads a layer's arcs from its own scan of the specs (not
    Sdf's GetCompositionAssetDependencies): it must reach what composing reads."""
    from pxr import Usd

    root = str(_write(tmp_path, REACHING))
    stage = Usd.Stage.OpenMasked(root, Usd.StagePopulationMask(), Usd.Stage.LoadAll)
    missing: list[tuple[Sdf.Layer, str]] = []
    scans = fastpath._Scans(fastpath._Specs(), lambda type_name: False)
    reached = fastpath._reachable_layers(stage, missing, scans)
    full = Usd.Stage.Open(root)
    files = {Path(layer.realPath).name for layer in reached if not layer.anonymous}
    assert files == {Path(layer.realPath).name for layer in full.GetUsedLayers() if layer.realPath}
    assert files == {"shot.usda", "layout.usda", "a.usda", "a_base.usda", "p.usda", "set.usda"}
    assert [Path(asset_path).name for _, asset_path in missing] == ["missing.usda"]


def test_a_stage_of_sublayers_only_is_composed_without_scanning_a_spec(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """No layer of the root layer stack holds a reference or payload word: every
    layer is in it, so a full composition reads them all once (layer_words.py)."""

    def refuse(*_args, **_kwargs):
        raise AssertionError("a layer was scanned")

    monkeypatch.setattr(fastpath, "FLAT_STAGES_COMPOSE_FULLY", True)
    monkeypatch.setattr(fastpath, "_scan", refuse)
    root = _write(
        tmp_path,
        {
            "shot.usda": "#usda 1.0\n(\n    subLayers = [@./lighting.usda@, @./layout.usda@]\n)\n",
            "lighting.usda": '#usda 1.0\ndef Scope "Render"\n{\n    def RenderSettings "S"\n'
            "    {\n    }\n}\n",
            "layout.usda": '#usda 1.0\ndef Xform "World"\n{\n    def Camera "cam"\n'
            "    {\n    }\n}\n",
        },
    )
    opened = fastpath.open_partial(str(root), lambda type_name: True)
    assert opened.stage is None
    assert opened.reason == "every layer is in the root layer stack"
