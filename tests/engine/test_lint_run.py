"""One lint, one value: a LintRun carries what every caller of the engine needs
(findings, each finding's Fix and origin, what was read, how the stage was
composed, whether the lint completed), from a single call, with no mode set
on the Linter."""

from __future__ import annotations

from pathlib import Path

from pxr import Sdf, Usd

from usdrender_lint.engine import Linter
from usdrender_lint.engine.variants import VariantExplorer
from usdrender_lint.running import result_cache
from usdrender_lint.testing import all_rules

RULES = Path(__file__).parents[1] / "rules"
CA004 = RULES / "CA004_camera_target_not_camera"
FROM_REFERENCE = CA004 / "fail_from_reference.usda"

SETTINGS = """#usda 1.0
(
    renderSettingsPrimPath = "/Render/Settings"
)

def Xform "World" (
    references = @./set.usda@</Set>
)
{
}

def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel camera = </World/cam>
        int2 resolution = (0, 1080)
        rel products = </Render/Product>
    }

    def RenderProduct "Product"
    {
        token productName = "beauty.exr"
        rel orderedVars = </Render/Color>
    }

    def RenderVar "Color"
    {
        string sourceName = "Ci"
    }
}
"""

SET = """#usda 1.0

def Xform "Set"
{
    def Camera "cam"
    {
    }

    def Xform "props"
    {
    }
}
"""


def test_one_lint_carries_its_findings_fixes_origins_and_reads() -> None:
    linter = Linter(all_rules())
    run = linter.run_path(str(FROM_REFERENCE), reads=True)
    assert run.completed and run.composed == "full"
    assert run.result == linter.lint_path(str(FROM_REFERENCE))
    by_code = {finding.code: finding for finding in run.findings}
    # Each finding's Fix, the callable its FixInfo describes.
    fix = run.fix(by_code["CA004"])
    assert fix is not None and fix.apply is not None
    assert by_code["CA004"].fix is not None
    assert fix.description == by_code["CA004"].fix.description
    assert {f.code for f in run.findings if run.fix(f)} == {f.code for f in run.findings if f.fix}
    # The rule and check_prim prim behind each finding.
    assert run.origin(by_code["SE015"]) == ("SE015", Sdf.Path("/Shot/Render/Settings"))
    assert run.origin(by_code["ST003"]) == ("ST003", None)  # a check_stage finding
    traced = {t.finding.code: t for t in run.traced()}
    assert traced["SE015"].prim_path == Sdf.Path("/Shot/Render/Settings")
    assert traced["CA004"].fix is fix
    # What the lint read: the referenced layer too.
    assert run.reads is not None and run.reads.complete
    read = {real for _, real, _, _ in run.reads.layers}
    assert str((CA004 / "rig_layer.usda").resolve()) in read


def test_reads_are_recorded_only_when_asked() -> None:
    linter = Linter(all_rules())
    assert linter.run_path(str(FROM_REFERENCE)).reads is None
    stage = Usd.Stage.Open(str(FROM_REFERENCE))
    assert linter.run_stage(stage).reads is None
    assert linter.run_stage(stage, reads=True).reads is not None


def test_the_fast_path_says_it_composed_part_of_the_stage(tmp_path: Path) -> None:
    (tmp_path / "set.usda").write_text(SET)
    shot = tmp_path / "shot.usda"
    shot.write_text(SETTINGS)
    fast = Linter(all_rules()).run_path(str(shot), reads=True)
    full = Linter(all_rules(), full_composition=True).run_path(str(shot), reads=True)
    assert (fast.composed, full.composed) == ("partial", "full")
    assert fast.completed and full.completed
    assert fast.result == full.result and "SE001" in {f.code for f in fast.findings}
    (finding,) = [f for f in fast.findings if f.code == "SE001"]
    assert fast.origin(finding) == full.origin(finding) == ("SE001", Sdf.Path("/Render/Settings"))
    # The fast path read the referenced layer's specs to prove its mask exact.
    assert fast.reads is not None
    assert str(tmp_path / "set.usda") in {real for _, real, _, _ in fast.reads.layers}


def test_a_lint_that_stops_says_so(tmp_path: Path) -> None:
    broken = tmp_path / "broken.usda"
    broken.write_text('#usda 1.0\ndef Scope "Render" {\n')
    run = Linter(all_rules()).run_path(str(broken), reads=True)
    assert not run.completed and run.composed is None
    assert [f.code for f in run.findings] == ["ST001"]
    assert run.fixes == {} and run.origins == {}
    missing = Linter(all_rules()).run_path(str(tmp_path / "none.usda"))
    assert not missing.completed and missing.result.status == "error"


def test_lints_of_one_linter_share_nothing(tmp_path: Path) -> None:
    # Each call returns its own value: a lint inside another (a rule, a host
    # application's validator) cannot take the other's fixes, origins or reads.
    linter = Linter(all_rules())
    outer = linter.run_path(str(FROM_REFERENCE), reads=True)
    inner = linter.run_stage(Usd.Stage.Open(str(CA004 / "fail_rig.usda")))
    again = linter.run_path(str(FROM_REFERENCE), reads=True)
    assert inner.reads is None and outer.reads is not again.reads
    assert outer.result == again.result
    assert [outer.origin(f) for f in outer.findings] == [again.origin(f) for f in again.findings]
    assert not set(outer.fixes) & set(inner.fixes)


VARIANT_SHOT = """#usda 1.0

def Scope "Render" (
    variants = {
        string quality = "low"
    }
    prepend variantSets = "quality"
)
{
    def RenderSettings "Settings"
    {
        int2 resolution = (1920, 1080)
    }
    variantSet "quality" = {
        "high" {
            over "Settings" (
                prepend references = @./high.usda@</Settings>
            )
            {
            }
        }
        "low" {
        }
    }
}
"""

HIGH = """#usda 1.0

def RenderSettings "Settings"
{
    float4 dataWindowNDC = (1, 0, 0, 1)
}
"""


def test_the_variant_explorer_gives_one_value_for_every_combination(tmp_path: Path) -> None:
    (tmp_path / "high.usda").write_text(HIGH)
    shot = tmp_path / "shot.usda"
    shot.write_text(VARIANT_SHOT)
    linter = Linter(all_rules(), full_composition=True)
    run = VariantExplorer(linter).run_path(str(shot), reads=True)
    plain = linter.run_path(str(shot), reads=True)
    assert run.completed and run.reads is not None and plain.reads is not None
    # Only the "high" combination reads high.usda: the explorer's reads hold it.
    high = str(tmp_path / "high.usda")
    assert high in {real for _, real, _, _ in run.reads.layers}
    assert high not in {real for _, real, _, _ in plain.reads.layers}
    se003 = [f for f in run.findings if f.code == "SE003"]
    assert se003 and "[variant selection: /Render{quality=high}]" in se003[0].message
    # Only another selection shows it: --fix, which explores none, cannot apply a fix.
    assert run.fix(se003[0]) is None and se003[0].fix is None


def test_one_run_answers_the_check_the_cache_and_the_fixer_on_corpus_files(
    shared_dir: Path,
) -> None:
    files = sorted((shared_dir / "corpus" / "files").rglob("*.usd*"))
    render = [p for p in files if p.suffix != ".usdz" and b"Render" in p.read_bytes()]
    assert len(render) > 20, len(render)
    linter = Linter(all_rules())
    fixed = 0
    for path in render:
        run = linter.run_path(str(path), reads=True)
        assert run.result == linter.lint_path(str(path)), path  # what check reports
        for finding in run.findings:  # what the fixer applies: the Fix each FixInfo names
            fix = run.fix(finding)
            assert (fix is None) == (finding.fix is None), (path, finding)
            if fix is not None and finding.fix is not None:
                assert (fix.description, fix.safe) == (finding.fix.description, finding.fix.safe)
                fixed += 1
        if not run.completed:
            continue
        # What the cache keys the result on covers every layer the stage uses.
        assert run.reads is not None
        found = result_cache.dependencies(run.reads, str(path))
        if found is not None:
            stage = Usd.Stage.Open(str(path))
            used = {x.realPath for x in stage.GetUsedLayers() if not x.anonymous and x.realPath}
            assert used <= {str(path), *found.files}, path
    assert fixed > 10, fixed
