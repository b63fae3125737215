"""What deciding the profiles reads (issue 27: on a CI gate of many shots it
ran for every render prim of every shot): each render prim's properties once
in ``auto``, and nothing of the stage under an explicit profile."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import pytest
from pxr import Sdf, Usd
from rule_support import patch_usd

from usdrender_lint.api import resolve
from usdrender_lint.api.resolve import prim_values
from usdrender_lint.engine import Linter
from usdrender_lint.profiles import Profiler, detect
from usdrender_lint.testing import all_rules

#: Two settings sharing a product, three products sharing two vars: the
#: evidence (karma:) is on a shared var, so both settings are karma's.
SHARING = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "A"
    {
        rel camera = </Cam>
        rel products = [</Render/P1>, </Render/P2>]
        token aspectRatioConformPolicy = "expandAperture"
        float pixelAspectRatio = 1
    }
    def RenderSettings "B"
    {
        rel camera = </Cam>
        rel products = [</Render/P2>, </Render/P3>]
    }
    def RenderProduct "P1"
    {
        rel camera = </Cam>
        rel orderedVars = [</Render/Color>, </Render/Depth>]
        token productName = "p1.exr"
    }
    def RenderProduct "P2"
    {
        rel orderedVars = [</Render/Color>, </Render/Depth>]
        token productName = "p2.exr"
    }
    def RenderProduct "P3"
    {
        rel orderedVars = </Render/Color>
        token productName = "p3.exr"
    }
    def RenderVar "Color"
    {
        string sourceName = "Ci"
        int karma:aov:samples = 2
    }
    def RenderVar "Depth"
    {
        string sourceName = "z"
    }
}
def Camera "Cam"
{
}
"""

#: The reads of a prim's properties that deciding a profile may make.
_PROPERTY_READS = ("GetAuthoredPropertyNames", "GetAuthoredAttributes", "GetAuthoredProperties")
_READS = (*_PROPERTY_READS, "GetRelationship", "GetAttribute", "IsA")


def _count_reads(monkeypatch: pytest.MonkeyPatch, counts: Counter) -> None:
    """Count each read of ``_READS`` per prim path and method (and per
    property name, as ``(path, method, name)``)."""
    for name in _READS:
        real = getattr(Usd.Prim, name)

        def spy(prim, *args, _real=real, _name=name):
            counts[str(prim.GetPath()), _name] += 1
            if args and isinstance(args[0], str):
                counts[str(prim.GetPath()), _name, args[0]] += 1
            return _real(prim, *args)

        patch_usd(monkeypatch, Usd.Prim, name, spy)


def _decide(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, setting: str) -> tuple[Counter, set]:
    """Lint SHARING, counting the reads its profiler makes; the profiles of its findings."""
    path = tmp_path / "shot.usda"
    path.write_text(SHARING, encoding="utf-8")
    counts: Counter = Counter()
    profiler = Profiler(lambda file: (setting, "test"))

    def counting(ctx):
        with monkeypatch.context() as patch:
            _count_reads(patch, counts)
            return profiler(ctx)

    linter = Linter(all_rules(), raise_errors=True, profiler=counting)
    result = linter.lint_path(str(path))
    assert result.status == "linted", result.error
    return counts, {f.profile for f in result.findings}


def test_auto_reads_each_render_prims_properties_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A render schema's IsA answer is kept for the process per prim type: none yet.
    monkeypatch.setattr(resolve, "_SCHEMA_IS_A", {})
    counts, profiles = _decide(tmp_path, monkeypatch, "auto")
    assert profiles == {"karma"}
    render_prims = {f"/Render/{name}" for name in ("A", "B", "P1", "P2", "P3", "Color", "Depth")}
    listed = _listed(counts)
    # One listing of its properties per render prim, however many scopes share it.
    assert listed == Counter({path: 1 for path in render_prims})
    # A var several products target is asked its type once, and the second
    # var of the same type not at all.
    assert counts["/Render/Color", "IsA"] + counts["/Render/Depth", "IsA"] == 1
    # A relationship no layer authors is not asked for (P2's camera), nor is
    # a productType no layer authors (the schema's fallback says it).
    assert counts["/Render/P2", "GetRelationship"] == 1  # orderedVars only
    assert not [key for key in counts if key[1] == "GetAttribute"]


def _listed(counts: Counter) -> Counter:
    """How often each prim's properties were listed."""
    return Counter(
        key[0] for key, n in counts.items() if key[1] in _PROPERTY_READS for _ in range(n)
    )


def test_the_profiles_and_the_rules_share_their_reads(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Deciding the profiles reads the render prims through the lint's
    PrimValues, which the rules read after: a whole lint in ``auto`` lists
    no prim's names and asks for no property more often than a lint under
    the profile it infers, which decides nothing."""
    path = tmp_path / "shot.usda"
    path.write_text(SHARING, encoding="utf-8")
    reads = {}
    for setting in ("auto", "karma"):
        counts: Counter = Counter()
        linter = Linter(
            all_rules(), raise_errors=True, profiler=Profiler(lambda f, s=setting: (s, ""))
        )
        with monkeypatch.context() as patch:
            _count_reads(patch, counts)
            result = linter.lint_path(str(path))
        assert result.status == "linted", result.error
        assert {f.profile for f in result.findings} == {"karma"}
        reads[setting] = {k: n for k, n in counts.items() if k[1] != "IsA"}
    assert reads["auto"] == reads["karma"]
    # Each render prim's names are listed once in the whole lint.
    listed = _listed(Counter(reads["auto"]))
    assert set(listed.values()) == {1}, listed


def test_an_authored_product_type_is_read_and_a_fallback_is_the_schemas(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert _product_type_of(tmp_path, 'uniform token productType = "deep"') == "deep"
    assert _product_type_of(tmp_path, "uniform token productType") == "raster"
    assert _product_type_of(tmp_path, "") == "raster"


def _product_type_of(tmp_path: Path, authored: str) -> str | None:
    path = tmp_path / "product.usda"
    path.write_text(f'#usda 1.0\ndef RenderProduct "P"\n{{\n    {authored}\n}}\n')
    stage = Usd.Stage.Open(str(path))
    values = prim_values(stage.GetPrimAtPath("/P"))
    return detect._Scan(stage).reads(values, detect._PRODUCT)[2]


def test_an_explicit_profile_reads_nothing_of_the_stage(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    counts, profiles = _decide(tmp_path, monkeypatch, "arnold")
    assert profiles == {"arnold"}
    assert not counts


def test_prim_values_give_the_definition_key_the_profiles_read() -> None:
    """The applied API schemas auto reads as evidence come from the prim's
    PrimValues, which the rules' schema lookups share: the authored ones,
    known to USD or not."""
    stage = Usd.Stage.CreateInMemory()
    stage.GetRootLayer().ImportFromString(
        '#usda 1.0\ndef RenderSettings "S" (\n'
        '    prepend apiSchemas = ["KarmaRendererSettingsAPI", "CollectionAPI:x"]\n)\n{\n}\n'
    )
    values = prim_values(stage.GetPrimAtPath("/S"))
    assert values.definition_key() == (
        "RenderSettings",
        ("KarmaRendererSettingsAPI", "CollectionAPI:x"),
    )
    assert values.schema_attribute("resolution").type_name == Sdf.ValueTypeNames.Int2
