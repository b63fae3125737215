"""--variants: defects inside variants that are not selected."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner
from pxr import Usd

import usdrender_lint
from usdrender_lint.cli import cli
from usdrender_lint.engine import Linter
from usdrender_lint.engine.variants import VariantExplorer, combination_count, render_variant_sets
from usdrender_lint.testing import all_rules

# The authored selections are clean; quality=final zeroes the pixel aspect
# ratio (SE002) and camera=none leaves the settings without a camera (CA001).
SHOT = """#usda 1.0
(
    renderSettingsPrimPath = "/Render/Settings"
)

def Xform "World"
{
    def Camera "cam"
    {
    }
}

def Scope "Render" (
    variants = {
        string quality = "preview"
    }
    prepend variantSets = "quality"
)
{
    def RenderSettings "Settings" (
        variants = {
            string camera = "main"
        }
        prepend variantSets = "camera"
    )
    {
        rel products = </Render/Beauty>
        int2 resolution = (1920, 1080)
        uniform token aspectRatioConformPolicy = "expandAperture"
        variantSet "camera" = {
            "main" {
                rel camera = </World/cam>
            }
            "none" {
            }
        }
    }

    def RenderProduct "Beauty"
    {
        token productName = "beauty.exr"
        rel orderedVars = </Render/Color>
    }

    def RenderVar "Color"
    {
        string sourceName = "Ci"
    }

    variantSet "quality" = {
        "final" {
            over "Settings"
            {
                float pixelAspectRatio = 0
            }
        }
        "preview" {
        }
    }
}
"""
SETTINGS_LINE = SHOT.splitlines().index('    def RenderSettings "Settings" (') + 1


@pytest.fixture
def shot(tmp_path: Path) -> Path:
    path = tmp_path / "shot.usda"
    path.write_text(SHOT)
    return path


def check(*args: str):
    result = CliRunner().invoke(cli, ["check", "--isolated", "--format", "json", *args])
    document = json.loads(result.stdout) if result.stdout.startswith("{") else None
    findings = [f for file in document["files"] for f in file["findings"]] if document else []
    return result, findings


def test_without_variants_the_shot_is_clean(shot: Path) -> None:
    result, findings = check(str(shot))
    assert result.exit_code == 0, result.output
    assert findings == []


def test_variants_find_defects_in_unselected_variants_and_name_the_selection(
    shot: Path,
) -> None:
    before = (shot.read_bytes(), shot.stat().st_mtime_ns, sorted(os.listdir(shot.parent)))
    result, findings = check("--variants", str(shot))
    assert result.exit_code == 1, result.output
    by_code = {f["code"]: f for f in findings}
    assert set(by_code) == {"SE002", "CA001"}
    assert by_code["SE002"]["path"] == "/Render/Settings.pixelAspectRatio"
    assert by_code["SE002"]["message"].endswith("[variant selection: /Render{quality=final}]")
    assert by_code["CA001"]["message"].endswith(
        "[variant selection: /Render/Settings{camera=none}]"
    )
    # The selections were authored on a session layer only: the finding is
    # located in the user's file, and that file was neither written nor joined.
    assert by_code["CA001"]["layer"] == str(shot.resolve())
    assert by_code["CA001"]["line"] == SETTINGS_LINE
    assert (shot.read_bytes(), shot.stat().st_mtime_ns, sorted(os.listdir(shot.parent))) == before


def test_the_cap_limits_the_combinations_and_says_how_many_it_skipped(shot: Path) -> None:
    # Authored first: (preview, main); then one set at a time, by prim path:
    # (final, main), (preview, none); then (final, none).
    result, one = check("--variants", "--max-variant-combinations", "1", str(shot))
    assert one == []
    assert result.stderr == (
        f"usdrender-lint: {shot}: --variants linted 1 variant combination; 3 more were "
        "skipped (raise --max-variant-combinations)\n"
    )
    result, two = check("--variants", "--max-variant-combinations", "2", str(shot))
    assert {f["code"] for f in two} == {"SE002"}
    assert "2 variant combinations; 2 more were skipped" in result.stderr
    result, three = check("--variants", "--max-variant-combinations", "3", str(shot))
    assert "3 variant combinations; 1 more was skipped" in result.stderr
    assert {f["code"] for f in three} == {"SE002", "CA001"}
    result, four = check("--variants", "--max-variant-combinations", "4", str(shot))
    assert four == three and result.stderr == ""  # nothing skipped, nothing said


def test_a_finding_under_the_authored_selection_is_not_annotated(tmp_path: Path) -> None:
    path = tmp_path / "shot.usda"
    path.write_text(SHOT.replace('string sourceName = "Ci"', 'string sourceName = ""'))
    _, findings = check("--variants", "--select", "VA001", str(path))
    assert len(findings) == 1
    assert "variant selection" not in findings[0]["message"]


def test_variant_sets_of_render_prims_and_ancestors(shot: Path) -> None:
    stage = Usd.Stage.Open(str(shot))
    sets = render_variant_sets(stage)
    assert [(str(s.prim_path), s.name, s.choices) for s in sets] == [
        ("/Render", "quality", ("preview", "final")),
        ("/Render/Settings", "camera", ("main", "none")),
    ]
    assert combination_count(sets) == 4


def test_the_session_layer_is_reset_and_a_plain_file_lints_as_usual(shot: Path) -> None:
    explorer = VariantExplorer(Linter(all_rules()), max_combinations=8)
    stage = Usd.Stage.Open(str(shot))
    codes = {f.code for f in explorer.lint_stage(stage)}
    assert codes == {"SE002", "CA001"}
    assert len(stage.GetSessionLayer().rootPrims) == 0
    assert stage.GetPrimAtPath("/Render").GetVariantSet("quality").GetVariantSelection() == (
        "preview"
    )
    plain = Path(__file__).parents[1] / "rules/SE003_data_window_malformed/fail_inverted.usda"
    assert explorer.lint_path(str(plain)) == Linter(all_rules()).lint_path(str(plain))


def test_the_python_api_explores_variants_too(shot: Path) -> None:
    assert usdrender_lint.lint_file(shot).findings == ()
    codes = {f.code for f in usdrender_lint.lint_file(shot, variants=True).findings}
    assert codes == {"SE002", "CA001"}


def test_variants_refuse_fixing(shot: Path) -> None:
    result = CliRunner().invoke(cli, ["check", "--isolated", "--variants", "--fix", str(shot)])
    assert result.exit_code == 2
    assert "cannot be combined with --fix" in result.output


def test_a_finding_only_under_another_selection_offers_no_fix(tmp_path: Path) -> None:
    """--fix refuses --variants, and without it the finding is not on the stage
    to fix: the report said "fixable with --fix" all the same."""
    path = tmp_path / "shot.usda"
    path.write_text(
        SHOT.replace("float pixelAspectRatio = 0", 'uniform token[] includedPurposes = ["render"]')
    )
    args = ("--variants", "--select", "SE010", str(path))
    _, findings = check(*args)
    (finding,) = findings
    assert finding["message"].endswith("[variant selection: /Render{quality=final}]")
    assert finding["fix"] is None
    text = CliRunner().invoke(cli, ["check", "--isolated", *args])
    assert "fixable" not in text.output and "[fix:" not in text.output


def test_config_variants_refuse_fixing_and_say_how_to_fix_all_the_same(shot: Path) -> None:
    (shot.parent / ".usdrender-lint.toml").write_text("variants = true\n")
    result = CliRunner().invoke(cli, ["check", "--fix", str(shot)])
    assert result.exit_code == 2
    assert "--config 'variants = false'" in result.output
    result = CliRunner().invoke(cli, ["check", "--fix", "--config", "variants = false", str(shot)])
    assert result.exit_code == 0, result.output


def test_a_missing_file_is_reported_as_usual(tmp_path: Path) -> None:
    explorer = VariantExplorer(Linter(all_rules()))
    result = explorer.lint_path(str(tmp_path / "missing.usda"))
    assert result.status == "error" and "no such file" in result.error


def test_variants_and_their_cap_from_the_config_file(shot: Path) -> None:
    config = shot.parent / ".usdrender-lint.toml"
    config.write_text("variants = true\nmax-variant-combinations = 2\n")
    result = CliRunner().invoke(cli, ["check", "--format", "json", str(shot)])
    codes = {f["code"] for file in json.loads(result.stdout)["files"] for f in file["findings"]}
    assert codes == {"SE002"}  # the cap of 2 from the file applies
    flag = CliRunner().invoke(
        cli, ["check", "--format", "json", "--max-variant-combinations", "64", str(shot)]
    )
    codes = {f["code"] for file in json.loads(flag.stdout)["files"] for f in file["findings"]}
    assert codes == {"SE002", "CA001"}  # the flag wins over the file


def test_variants_config_value_is_validated(shot: Path) -> None:
    (shot.parent / ".usdrender-lint.toml").write_text('variants = "yes"\n')
    result = CliRunner().invoke(cli, ["check", str(shot)])
    assert result.exit_code == 2
    assert "'variants' must be true or false" in result.stderr


def _many_sets(count: int) -> str:
    """A RenderSettings with ``count`` variant sets of two variants each."""
    names = ", ".join(f'"v{i}"' for i in range(count))
    selections = "\n".join(f'            string v{i} = "a"' for i in range(count))
    bodies = "".join(
        f'        variantSet "v{i}" = {{\n            "a" {{\n            }}\n'
        '            "b" {\n                int2 resolution = (0, 0)\n            }\n        }\n'
        for i in range(count)
    )
    return (
        '#usda 1.0\ndef Scope "Render"\n{\n    def RenderSettings "S" (\n        variants = {\n'
        f"{selections}\n        }}\n        prepend variantSets = [{names}]\n    )\n    {{\n"
        f"{bodies}    }}\n}}\n"
    )


def test_many_variant_sets_cost_the_cap_not_their_combinations(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """10,000 variant sets took 1,118 s of CPU (1,000: 11 s): reading each
    set's variants walked the whole prim index once per set. Now the sets are
    read in one pass, exactly the cap's combinations are composed, and four
    times the sets cost about four times the Python calls."""
    from usdrender_lint.engine import variants

    authored: list[tuple] = []
    real = variants.author_selection
    monkeypatch.setattr(
        variants, "author_selection", lambda *a: (authored.append(a[2]), real(*a))[1]
    )
    linter = Linter(all_rules())

    def calls(count: int) -> int:
        path = tmp_path / f"sets{count}.usda"
        path.write_text(_many_sets(count))
        stage = Usd.Stage.Open(str(path))
        made = 0

        def counting(frame: object, event: str, arg: object) -> None:
            nonlocal made
            made += 1

        authored.clear()
        sys.setprofile(counting)
        try:
            run = VariantExplorer(linter, max_combinations=5).run_stage(stage)
        finally:
            sys.setprofile(None)
        findings, notes = run.findings, run.result.notes
        assert len(authored) == 5  # the cap, never the 2^count combinations
        assert any("v0=b" in f.message for f in findings)
        assert notes[0] == variants.skipped_note(str(path), 5, 2**count)
        return made

    calls(25)  # first-use costs out of the count
    ratio = calls(400) / calls(100)
    assert ratio < 6, ratio


def test_variant_sets_read_in_one_pass_match_usds_own_answer(tmp_path: Path) -> None:
    path = tmp_path / "sets.usda"
    path.write_text(_many_sets(30))
    stage = Usd.Stage.Open(str(path))
    variant_sets = stage.GetPrimAtPath("/Render/S").GetVariantSets()
    expected = [
        (
            name,
            variant_sets.GetVariantSet(name).GetVariantSelection(),
            variant_sets.GetVariantSet(name).GetVariantNames(),
        )
        for name in variant_sets.GetNames()
    ]
    found = [(s.name, s.authored, sorted(s.choices)) for s in render_variant_sets(stage)]
    assert found == [(name, chosen, sorted(names)) for name, chosen, names in expected]


# A variant that adds a product, one that deactivates the vars' scope, and a
# scope that copies /Render through an internal reference (USD recomposes it
# when a selection on /Render changes) with a suppression on the copy.
ARCS = """#usda 1.0

def Scope "Render" (
    variants = {
        string extra = "no"
        string vars = "on"
    }
    prepend variantSets = ["extra", "vars"]
)
{
    def RenderSettings "Settings"
    {
        rel products = </Render/Beauty>
    }

    def RenderProduct "Beauty"
    {
        rel orderedVars = </Render/Vars/Color>
    }

    def Scope "Vars"
    {
        def RenderVar "Color"
        {
        }
    }

    variantSet "extra" = {
        "no" {
        }
        "yes" {
            def RenderProduct "Extra"
            {
            }
        }
    }
    variantSet "vars" = {
        "off" {
            over "Vars" (
                active = false
            )
            {
            }
        }
        "on" {
        }
    }
}

def Scope "Copy" (
    customData = {
        dictionary usdrender_lint = {
            string[] ignore = ["ST008"]
        }
    }
    references = </Render>
)
{
}
"""


def test_each_combination_walks_only_what_usd_recomposed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """After the first walk a combination re-walks only the subtrees USD
    recomposed, and keeps exactly the prims a whole walk would."""
    from usdrender_lint.engine import variants

    path = tmp_path / "arcs.usda"
    path.write_text(ARCS)
    linter = Linter(all_rules())
    stage = Usd.Stage.Open(str(path))
    sets = render_variant_sets(stage)
    assert combination_count(sets) == 16  # /Copy has the sets too
    whole_walks = []
    walk_candidates = linter.walk_candidates

    def counted(stage, prims=None, own_stage=False):
        if prims is None:
            whole_walks.append(stage)
        return walk_candidates(stage, prims, own_stage)

    with variants._Walk(linter, stage, own_stage=True) as walk:
        seen = set()
        for combination in variants.combinations(sets, 16):
            variants.author_selection(stage, sets, combination)
            monkeypatch.setattr(linter, "walk_candidates", counted)
            kept = [p.GetPath() for p in walk.prims()]
            monkeypatch.setattr(linter, "walk_candidates", walk_candidates)
            assert kept == [p.GetPath() for p in walk_candidates(stage)]
            seen.add(tuple(kept))
    assert whole_walks == []
    assert len(seen) > 4  # the combinations compose other prims
    explored = VariantExplorer(linter).lint_path(str(path))
    stage.GetSessionLayer().Clear()
    assert explored.findings  # the same as a whole walk per combination:
    monkeypatch.setattr(variants._Walk, "prims", lambda self: walk_candidates(self._stage))
    assert VariantExplorer(linter).lint_path(str(path)).findings == explored.findings


def test_the_benchmark_s_variant_shot_has_64_combinations_and_their_defects(
    tmp_path: Path,
) -> None:
    """benchmarks/run.py --only variants lints this shot (at 100k prims)."""
    import sys

    sys.path.insert(0, str(Path(__file__).parents[1]))
    from bench_support import load_script

    shot = load_script("generate").generate_variant_shot(tmp_path, prims=300)
    stage = Usd.Stage.Open(str(shot))
    assert combination_count(render_variant_sets(stage)) == 64
    result = VariantExplorer(Linter(all_rules())).lint_path(str(shot))
    assert result.notes == ()
    selected = {f.code for f in result.findings if "[variant selection:" in f.message}
    assert {"SE002", "SE003"} <= selected


TWO_PLACES = """#usda 1.0
def Scope "Render" (
    prepend variantSets = ["q"]
    variants = {
        string q = "%s"
    }
)
{
    def RenderSettings "S" (
        customData = {
            dictionary usdrender_lint = {
                string[] ignore = %s
            }
        }
    )
    {
        uniform int2 resolution = (1920, 1080)
    }
    variantSet "q" = {
        "good" {
        }
        "bad1" {
            over "S" {
                uniform float pixelAspectRatio = 0
            }
        }
        "bad2" {
            over "S" {
                uniform float pixelAspectRatio = 0
            }
        }
    }
}
"""


def test_the_same_problem_in_two_variants_is_two_findings(tmp_path: Path) -> None:
    """One finding per place: the problem authored in variant bad1 (line 24)
    and in bad2 (line 29) is two findings, as a check of each selection says."""
    shot = tmp_path / "shot.usda"
    shot.write_text(TWO_PLACES % ("good", "[]"))
    found = usdrender_lint.lint_file(shot, variants=True, select=["SE002"]).findings
    assert sorted(f.location.line for f in found) == [24, 29]
    for variant, line in (("bad1", 24), ("bad2", 29)):
        shot.write_text(TWO_PLACES % (variant, "[]"))
        (plain,) = usdrender_lint.lint_file(shot, select=["SE002"]).findings
        assert plain.location.line == line


def test_a_suppression_one_combination_uses_is_not_unused(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(TWO_PLACES % ("bad1", '["SE002"]'))
    codes = {f.code for f in usdrender_lint.lint_file(shot, variants=True).findings}
    assert "SE002" not in codes and "UL001" not in codes
    # Unused under every selection, it is reported (once).
    shot.write_text(TWO_PLACES % ("good", '["SE001"]'))
    found = usdrender_lint.lint_file(shot, variants=True).findings
    assert [f.code for f in found].count("UL001") == 1


def test_recomposing_for_a_selection_writes_nothing_on_stderr(tmp_path: Path) -> None:
    """USD's warnings when a selection's recomposition meets a missing reference
    are the lint's findings (ST002), not lines on stderr."""
    shot = tmp_path / "shot.usda"
    shot.write_text(
        TWO_PLACES.replace('"S" (\n', '"S" (\n        references = @./missing.usda@\n')
        % ("good", "[]")
    )
    # In its own process: USD writes its warnings to the file descriptor, not sys.stderr.
    command = [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "--no-cache"]
    result = subprocess.run([*command, "--variants", str(shot)], capture_output=True, text=True)
    assert result.returncode == 1, result.stderr
    assert "ST002" in result.stdout
    assert result.stderr == ""


# No render prim is on the stage as authored: the variant "on" adds the settings.
ADDS_RENDER_PRIMS = """#usda 1.0
def Xform "World" (
    variants = {
        string render = "none"
    }
    prepend variantSets = "render"
)
{
    variantSet "render" = {
        "none" {
        }
        "on" {
            def RenderSettings "Settings"
            {
                uniform int2 resolution = (0, 10)
            }
        }
    }
}
"""


def test_a_variant_that_adds_render_prims_is_explored(tmp_path: Path) -> None:
    """Selecting "on" makes a render prim: its findings equal a check of a
    copy with that selection authored."""
    shot = tmp_path / "adds.usda"
    shot.write_text(ADDS_RENDER_PRIMS)
    selected = tmp_path / "selected.usda"
    selected.write_text(ADDS_RENDER_PRIMS.replace('render = "none"', 'render = "on"'))
    linter = Linter(all_rules())
    expected = [f for f in linter.lint_path(str(selected)).findings if f.code == "SE001"]
    assert expected
    found = VariantExplorer(linter).lint_path(str(shot)).findings
    explored = [f for f in found if f.code == "SE001"]
    assert [f.code for f in explored] == [f.code for f in expected]
    assert explored[0].location.path == expected[0].location.path
    assert "/World{render=on}" in explored[0].message


# The set "detail" exists only inside quality=high; its variant "b" zeroes the
# resolution (SE001).
NESTED = """#usda 1.0
def Scope "Render" (
    variants = {
        string quality = "low"
    }
    prepend variantSets = "quality"
)
{
    def RenderSettings "Settings"
    {
    }
    variantSet "quality" = {
        "low" {
        }
        "high" (
            variants = {
                string detail = "a"
            }
            prepend variantSets = "detail"
        ) {
            variantSet "detail" = {
                "a" {
                }
                "b" {
                    over "Settings"
                    {
                        uniform int2 resolution = (0, 10)
                    }
                }
            }
        }
    }
}
"""


def test_a_variant_set_nested_in_an_unselected_variant_is_explored(tmp_path: Path) -> None:
    shot = tmp_path / "nested.usda"
    shot.write_text(NESTED)
    selected = tmp_path / "selected.usda"
    selected.write_text(
        NESTED.replace('quality = "low"', 'quality = "high"').replace(
            'detail = "a"', 'detail = "b"'
        )
    )
    linter = Linter(all_rules())
    expected = [f for f in linter.lint_path(str(selected)).findings if f.code == "SE001"]
    assert expected
    result = VariantExplorer(linter).lint_path(str(shot))
    explored = [f for f in result.findings if f.code == "SE001"]
    assert [f.location.path for f in explored] == [f.location.path for f in expected]
    assert "/Render{quality=high}, /Render{detail=b}" in explored[0].message
    # low, high with detail=a, high with detail=b: nothing skipped
    stage = Usd.Stage.Open(str(shot))
    assert combination_count(render_variant_sets(stage)) == 3
    assert result.notes == ()


# /Scene's reference is missing under every selection; render=on adds a render
# prim under it whose own reference is missing too. /Render/Main's is missing
# under every selection, outside what the selection recomposes.
ERRORS_AROUND_A_VARIANT = """#usda 1.0
def Scope "Scene" (
    prepend references = @./missing_scene.usda@
)
{
    def Scope "Holder" (
        variants = {
            string render = "none"
        }
        prepend variantSets = "render"
    )
    {
        variantSet "render" = {
            "none" {
            }
            "on" {
                def RenderSettings "Settings" (
                    prepend references = @./missing_settings.usda@
                )
                {
                    uniform int2 resolution = (1920, 1080)
                }
            }
        }
    }
}

def Scope "Render"
{
    def RenderSettings "Main" (
        prepend references = @./missing_main.usda@
    )
    {
        uniform int2 resolution = (1920, 1080)
    }
}
"""


def test_a_combination_reports_the_composition_errors_a_full_lint_of_it_does(
    tmp_path: Path,
) -> None:
    """A combination's composition errors are the authored ones where USD did
    not recompose plus the recomposed prims' own: the same ST002 findings as a
    check of a copy with that selection authored, including the error of an
    ancestor that only the selection puts render data under."""
    shot = tmp_path / "shot.usda"
    shot.write_text(ERRORS_AROUND_A_VARIANT)
    selected = tmp_path / "selected.usda"
    selected.write_text(ERRORS_AROUND_A_VARIANT.replace('render = "none"', 'render = "on"'))
    linter = Linter(all_rules())
    expected = {
        (str(f.location.path), f.message.replace("selected.usda", "shot.usda"))
        for f in linter.lint_path(str(selected)).findings
        if f.code == "ST002"
    }
    assert {path for path, _ in expected} == {
        "/Scene",
        "/Scene/Holder/Settings",
        "/Render/Main",
    }
    found = VariantExplorer(linter).lint_path(str(shot)).findings
    note = " [variant selection: /Scene/Holder{render=on}]"
    explored = {
        (str(f.location.path), f.message.replace(note, "")) for f in found if f.code == "ST002"
    }
    assert explored == expected
    annotated = {
        str(f.location.path) for f in found if f.code == "ST002" and f.message.endswith(note)
    }
    assert annotated == {"/Scene", "/Scene/Holder/Settings"}


class _CountingStage:
    """A stage that counts its whole-stage composition error queries."""

    def __init__(self, stage: Usd.Stage) -> None:
        self._stage = stage
        self.asked = 0

    def GetCompositionErrors(self) -> list:  # noqa: N802 - USD's name
        self.asked += 1
        return self._stage.GetCompositionErrors()

    def __getattr__(self, name: str) -> object:
        return getattr(self._stage, name)


def test_a_combination_does_not_ask_the_whole_stage_for_its_composition_errors(
    tmp_path: Path,
) -> None:
    from usdrender_lint.engine.variants import _CompositionErrors, _Walk, author_selection

    shot = tmp_path / "shot.usda"
    shot.write_text(ERRORS_AROUND_A_VARIANT)
    stage = Usd.Stage.Open(str(shot))
    counting = _CountingStage(stage)
    linter = Linter(all_rules())
    with _Walk(linter, stage, own_stage=True) as walk:
        sets = render_variant_sets(stage, walk.prims())
        errors = _CompositionErrors(counting, walk)  # type: ignore[arg-type]
        authored = {str(e) for e in errors.now()}
        assert counting.asked == 1
        author_selection(stage, sets, ((0, "on"),))
        combined = {str(e) for e in errors.now()}
        assert counting.asked == 1  # the recomposed subtree's own errors only
        assert combined == {str(e) for e in stage.GetCompositionErrors()}
        assert combined > authored


def test_a_stage_with_instances_is_asked_whole_for_a_combination(tmp_path: Path) -> None:
    """A prototype's errors are reported at one of its instances: the
    recomposed subtree cannot say which, so the stage is asked."""
    from usdrender_lint.engine.variants import _CompositionErrors, _Walk, author_selection

    shot = tmp_path / "shot.usda"
    shot.write_text(
        ERRORS_AROUND_A_VARIANT
        + '\ndef Xform "A" (instanceable = true\n prepend references = </Scene>)\n{\n}\n'
        + 'def Xform "B" (instanceable = true\n prepend references = </Scene>)\n{\n}\n'
    )
    stage = Usd.Stage.Open(str(shot))
    assert stage.GetPrototypes()
    counting = _CountingStage(stage)
    with _Walk(Linter(all_rules()), stage, own_stage=True) as walk:
        sets = render_variant_sets(stage, walk.prims())
        errors = _CompositionErrors(counting, walk)  # type: ignore[arg-type]
        errors.now()
        author_selection(stage, sets, ((0, "on"),))
        combined = {str(e) for e in errors.now()}
        assert counting.asked == 2
        assert combined == {str(e) for e in stage.GetCompositionErrors()}
