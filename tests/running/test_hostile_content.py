"""Hostile content: every step of a run is bounded by --timeout, a corrupt
layer costs no more in the fast path than in a full composition, messages are
bounded before they are formatted, and --variants is bounded by its cap."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from cli_support import EMPTY_VARIANT_NAME, HANGS, settings_crate
from pxr import Sdf, Usd, UsdRender, Vt

from usdrender_lint.api.text import MAX_MESSAGE_CHARS, listing
from usdrender_lint.engine import Linter
from usdrender_lint.engine.variants import (
    VariantExplorer,
    author_selection,
    combinations,
    render_variant_sets,
)
from usdrender_lint.testing import all_rules

pytestmark = pytest.mark.heavy(seconds=36)

REPO = Path(__file__).resolve().parents[2]
CONTROL = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Control"
    {
        uniform token aspectRatioConformPolicy = "CropAperture"
        uniform float4 dataWindowNDC = (1, 1, 0, 0)
    }
}
"""
EMPTY_VARIANT = EMPTY_VARIANT_NAME.replace(
    "#usda 1.0\n", "#usda 1.0\n(\n    subLayers = [@./sub.usda@]\n)\n", 1
)

fifos = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs")


def lint(folder: Path, *args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    """The command in its own process: a hang fails the test instead of the
    suite (TimeoutExpired), and a crash cannot take pytest with it."""
    crash_reports = folder / "usd-crash-reports"
    crash_reports.mkdir(exist_ok=True)
    return subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", *args],
        capture_output=True,
        text=True,
        cwd=folder,
        env={**os.environ, "TMPDIR": str(crash_reports)},
        timeout=timeout,
    )


@pytest.fixture
def hanging(tmp_path: Path) -> Path:
    os.mkfifo(tmp_path / "pipe.usda")
    (tmp_path / "hangs.usda").write_text(HANGS)
    (tmp_path / "control.usda").write_text(CONTROL)
    return tmp_path


TIMED_OUT = (
    "usdrender-lint: error: hangs.usda: timed out after 2 s while USD opened the stage "
    "(raise --timeout, or 0 for no limit)"
)


@fifos
@pytest.mark.parametrize("mode", [["--fix"], ["--diff"], ["--fix-to", "fixes.usda"]])
def test_the_timeout_bounds_fixing(hanging: Path, mode: list[str]) -> None:
    stages = ["hangs.usda"] if mode[0] == "--fix-to" else ["hangs.usda", "control.usda"]
    result = lint(hanging, "--isolated", "--timeout", "2", *mode, *stages)
    assert result.returncode == 2
    assert TIMED_OUT in result.stderr.splitlines()
    if mode == ["--fix"]:  # the other stage is still fixed
        assert 'aspectRatioConformPolicy = "cropAperture"' in (hanging / "control.usda").read_text()
    if mode == ["--diff"]:
        assert '+        uniform token aspectRatioConformPolicy = "cropAperture"' in result.stdout


@fifos
def test_the_timeout_bounds_finding_the_roots_layers(hanging: Path) -> None:
    (hanging / ".usdrender-lint.toml").write_text('roots = ["*.usda"]\n')
    result = lint(hanging, "--timeout", "2", "control.usda")
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        "usdrender-lint: error: hangs.usda: finding the layers it uses timed out after 2 s "
        "(raise --timeout, or 0 for no limit)"
    ]
    assert "control.usda:7: error SE003 " in result.stdout  # the others are linted


@fifos
def test_a_changed_file_that_is_a_fifo_is_never_read_for_roots(hanging: Path) -> None:
    (hanging / ".usdrender-lint.toml").write_text('roots = ["control.usda"]\n')
    result = lint(hanging, "--timeout", "0", "--jobs", "1", "pipe.usda", timeout=120)
    assert result.returncode == 2
    assert result.stderr == "usdrender-lint: error: pipe.usda: not a regular file\n"


SUBLAYER_PIPE = "#usda 1.0\n(\n    subLayers = [@./pipe.usda@]\n)\n" + CONTROL.split("\n", 1)[1]
NAMED_PIPE = "not a regular file (a named pipe or a device, whose open can wait forever)"


@fifos
@pytest.mark.parametrize(
    "route",
    [
        ["--jobs", "1", "--timeout", "0", "shot.usda"],
        ["--jobs", "2", "shot.usda", "control.usda"],
        ["shot.usda"],
        ["-", "--stdin-filename", "shot.usda"],
        ["--fix", "shot.usda"],
    ],
    ids=["in process", "pool", "lone file", "standard input", "fix"],
)
def test_a_sublayer_that_is_a_named_pipe_is_st001_at_once_on_every_route(
    tmp_path: Path, route: list[str]
) -> None:
    """USD's open of a named pipe waits for a writer: the stage's lint waited out
    the time-out, which said to raise it, and without one (--timeout 0, the
    Python API) it never ended. Now the arc is refused before USD opens it."""
    os.mkfifo(tmp_path / "pipe.usda")
    (tmp_path / "shot.usda").write_text(SUBLAYER_PIPE)
    (tmp_path / "control.usda").write_text(CONTROL)
    done = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "--format", "json", *route],
        input=SUBLAYER_PIPE,
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=120,
    )
    assert done.returncode == 1, done.stderr
    [shot] = [entry for entry in json.loads(done.stdout)["files"] if entry["file"] == "shot.usda"]
    assert [(f["code"], f["message"]) for f in shot["findings"]] == [
        ("ST001", f"pipe.usda: {NAMED_PIPE}")
    ]
    assert (tmp_path / "shot.usda").read_text() == SUBLAYER_PIPE  # nothing to fix


@fifos
def test_a_root_whose_sublayer_is_a_named_pipe_is_st001_at_once(tmp_path: Path) -> None:
    """With ``roots``, a changed layer is linted in each root that uses it: finding
    the root's layers waited on the pipe as its lint did, until the time-out."""
    os.mkfifo(tmp_path / "pipe.usda")
    (tmp_path / "shot.usda").write_text(
        "#usda 1.0\n(\n    subLayers = [@./pipe.usda@, @./control.usda@]\n)\n"
    )
    (tmp_path / "control.usda").write_text(CONTROL)
    (tmp_path / ".usdrender-lint.toml").write_text('roots = ["shot.usda"]\n')
    result = lint(tmp_path, "--timeout", "0", "--jobs", "1", "control.usda", timeout=120)
    assert result.returncode == 1, result.stderr
    assert result.stdout.splitlines()[0] == f"shot.usda: error ST001: pipe.usda: {NAMED_PIPE}"


@fifos
def test_the_python_api_answers_a_reference_to_a_named_pipe(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "pipe.usda")
    shot = tmp_path / "shot.usda"
    shot.write_text('#usda 1.0\ndef Scope "A" (\n    references = @./pipe.usda@\n)\n{\n}\n')
    code = (
        "import sys, usdrender_lint\n"
        "[finding] = usdrender_lint.lint_file(sys.argv[1]).files[0].findings\n"
        "print(finding.code, finding.message)"
    )
    done = subprocess.run(
        [sys.executable, "-c", code, str(shot)], capture_output=True, text=True, timeout=120
    )
    assert done.stdout == f"ST001 {tmp_path / 'pipe.usda'}: {NAMED_PIPE}\n", done.stderr


# -- corrupt layers in the fast path ----------------------------------------------------


def _same_as_full_composition(folder: Path, *files: str, jobs: str = "1", timeout: str = "0"):
    fast = lint(
        folder, "--isolated", "--format", "json", "--jobs", jobs, "--timeout", timeout, *files
    )
    full = lint(
        folder,
        "--isolated",
        "--format",
        "json",
        "--full-composition",
        "--jobs",
        "1",
        "--timeout",
        "0",
        *files,
    )
    assert full.returncode == 1, full.stderr
    assert (fast.returncode, fast.stderr) == (1, ""), fast.stderr

    # USD names the anonymous session layer by its address, which differs per process.
    def same(text: str) -> list:
        return json.loads(re.sub(r"anon:0x[0-9a-f]+", "anon:", text))["files"]

    assert same(fast.stdout) == same(full.stdout)
    return json.loads(fast.stdout)


def test_a_crate_naming_a_prim_with_no_name_survives_the_fast_path_in_process(
    tmp_path: Path,
) -> None:
    """One flipped byte: a prim named "". Sdf's layer walks abort the process on
    it (``GetCompositionAssetDependencies``); composing the stage posts an error."""
    data = bytearray(settings_crate(tmp_path / "settings.usdc"))
    if len(data) != 1219:
        pytest.skip("usd-core writes another crate layout; the corrupt byte is elsewhere")
    data[102] = 210
    (tmp_path / "corrupt.usdc").write_bytes(data)
    (tmp_path / "control.usda").write_text(CONTROL)
    report = _same_as_full_composition(tmp_path, "corrupt.usdc", "control.usda")
    corrupt, control = report["files"]
    assert {f["code"] for f in corrupt["findings"]} == {"ST001"}
    assert "SE003" in {f["code"] for f in control["findings"]}


def test_a_text_layer_naming_a_variant_with_no_name_survives_the_fast_path_in_process(
    tmp_path: Path,
) -> None:
    (tmp_path / "sub.usda").write_text("#usda 1.0\n")
    (tmp_path / "shot.usda").write_text(EMPTY_VARIANT)
    (tmp_path / "control.usda").write_text(CONTROL)
    report = _same_as_full_composition(tmp_path, "shot.usda", "control.usda")
    assert "ST003" in {f["code"] for f in report["files"][0]["findings"]}


def test_recording_what_a_failed_composition_read_survives_such_a_layer(tmp_path: Path) -> None:
    """With a composition error the result cache lists the layers' arcs
    (``GetCompositionAssetDependencies``), which aborts on a variant named ""."""
    (tmp_path / "sub.usda").write_text("#usda 1.0\n")
    (tmp_path / "shot.usda").write_text(
        EMPTY_VARIANT.replace("@./sub.usda@", "@./sub.usda@, @./missing.usda@")
    )
    result = lint(tmp_path, "--isolated", "--jobs", "1", "--timeout", "0", "shot.usda")
    assert (result.returncode, result.stderr) == (1, "")
    assert "error ST002: Could not load sublayer" in result.stdout


def test_a_worker_that_dies_in_the_fast_path_lints_the_file_fully_composed(tmp_path: Path) -> None:
    """A crate naming a variant "" (usd-core writes one from a .usda that names
    one): Sdf's walks recurse on it without end, composing it is fine."""
    (tmp_path / "source.usda").write_text(
        EMPTY_VARIANT.replace("    subLayers = [@./sub.usda@]\n", "")
    )
    Sdf.Layer.FindOrOpen(str(tmp_path / "source.usda")).Export(str(tmp_path / "variant.usdc"))
    (tmp_path / "control.usda").write_text(CONTROL)
    report = _same_as_full_composition(
        tmp_path, "variant.usdc", "control.usda", jobs="2", timeout="60"
    )
    assert "ST003" in {f["code"] for f in report["files"][0]["findings"]}


# -- messages are bounded before they are formatted ---------------------------------------


def test_a_listing_reads_only_what_it_shows() -> None:
    consumed = []

    def values():
        for value in range(10**9):
            consumed.append(value)
            yield value

    text = listing(values(), limit=50)
    assert text.startswith("0, 1, 2, ") and text.endswith(", …")
    assert len(consumed) < 40  # not a billion


def test_a_listing_of_a_vt_array_counts_the_rest_without_reading_them() -> None:
    text = listing(Vt.TokenArray(["default"] * 1_000_000), lambda v: f'"{v}"')
    assert len(text) < 600
    assert text.endswith(f"… ({1_000_000 - text.count('default'):,} more)")


def test_a_huge_purpose_list_gives_a_bounded_message_that_still_says_what_is_wrong(
    tmp_path: Path,
) -> None:
    path = tmp_path / "purposes.usdc"
    layer = Sdf.Layer.CreateNew(str(path))
    stage = Usd.Stage.Open(layer)
    settings = UsdRender.Settings.Define(stage, "/Render/Settings")
    settings.CreateIncludedPurposesAttr(Vt.TokenArray(["default", "render"] * 100_000))
    layer.Save()
    findings = Linter(all_rules(), raise_errors=True).lint_path(str(path)).findings
    [se009] = [f for f in findings if f.code == "SE009"]
    assert len(se009.message) < MAX_MESSAGE_CHARS
    assert se009.message.startswith('includedPurposes ["default", "render", "default", ')
    assert "more)]" in se009.message
    assert se009.message.endswith(
        '"default", "render" are listed more than once; the first 10,000 of 200,000 entries '
        "checked; list each of default, render, proxy, guide at most once"
    )
    assert se009.fix is None  # the fix needs the whole list checked


# -- --variants is bounded by its cap -----------------------------------------------------


def _many_variant_sets(count: int) -> Usd.Stage:
    layer = Sdf.Layer.CreateAnonymous(".usda")
    render = Sdf.CreatePrimInLayer(layer, "/Render")
    render.specifier = Sdf.SpecifierDef
    settings = Sdf.PrimSpec(render, "Settings", Sdf.SpecifierDef, "RenderSettings")
    with Sdf.ChangeBlock():
        for index in range(count):
            variant_set = Sdf.VariantSetSpec(settings, f"set{index}")
            Sdf.VariantSpec(variant_set, "a")
            Sdf.VariantSpec(variant_set, "b")
        settings.variantSetNameList.prependedItems = [f"set{i}" for i in range(count)]
    return Usd.Stage.Open(layer)


class CountingLinter(Linter):
    def __init__(self) -> None:
        super().__init__(all_rules())
        self.lints = 0

    def run_stage(self, stage, file=None, **options):
        self.lints += 1
        return super().run_stage(stage, file, **options)


def test_ten_thousand_variant_sets_are_linted_cap_times_one_selection_each() -> None:
    stage = _many_variant_sets(10_000)
    sets = render_variant_sets(stage)
    assert len(sets) == 10_000
    chosen = list(combinations(sets, 64))
    assert len(chosen) == 64 and chosen[0] == ()
    # After the authored selections (none: ""), each other variant of each set
    # alone: a combination costs one selection, however many sets there are.
    assert all(len(combination) == 1 for combination in chosen[1:])
    assert [c[0] for c in chosen[1:5]] == [(0, "a"), (0, "b"), (1, "a"), (1, "b")]
    author_selection(stage, sets, chosen[5])
    assert [str(p.path) for p in stage.GetSessionLayer().rootPrims] == ["/Render"]
    stage.GetSessionLayer().Clear()
    linter = CountingLinter()
    notes = VariantExplorer(linter, 64).run_stage(stage, "shot.usda").result.notes
    assert linter.lints == 64  # one composition and lint per combination, not per set
    assert notes == (
        "shot.usda: --variants linted 64 variant combinations; about 10^4771 more were skipped "
        "(raise --max-variant-combinations)",
    )


def test_after_each_set_alone_come_the_other_combinations() -> None:
    stage = _many_variant_sets(3)
    sets = render_variant_sets(stage)
    chosen = list(combinations(sets, 100))
    assert len(chosen) == 3**3 == len(set(chosen))  # "", "a" and "b" for each set
    assert [len(c) for c in chosen[:7]] == [0] + [1] * 6
    assert min(len(c) for c in chosen[7:]) == 2  # then in product order
