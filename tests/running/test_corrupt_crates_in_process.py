"""Corrupt crates in the command's own process (``--jobs 1 --timeout 0``):
whatever composing the stage survives, the run survives; a crate USD finds
corrupt (while composing, walking its specs or a rule reading a value) is
ST001, never UL000 or a file the tool "could not lint"; the other files are
still linted, and the exit code says an error was found."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from cli_support import EMPTY_VARIANT_NAME
from pxr import Sdf, Usd

from usdrender_lint.running.workers import lint_one

REPO = Path(__file__).resolve().parents[2]
CONTROL = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Control"
    {
        uniform float4 dataWindowNDC = (1, 1, 0, 0)
    }
}
"""
#: The crate usd-core 26.11 writes for examples/clean_shot/shot.usda flattened,
#: and bytes whose flip (``^ 0xFF``) each made the in-process run go wrong.
SHOT_CRATE_SIZE = 3211
FLIPS = {
    161: "the file holds a property with no name; the file is corrupt",  # was "internal error"
    196: "the file holds a property with no name; the file is corrupt",  # was UL000 per rule
    2314: "USD cannot read a value of the file: Attempted to unpack unsupported type enum "
    "value 64; the file is corrupt",  # was UL000
    2985: "USD cannot read the specs of flip2985.usdc (a spec of no valid type); the file is "
    "corrupt",  # was a segmentation fault reading a property stack
}


def lint(folder: Path, *args: str) -> subprocess.CompletedProcess:
    """In its own process, so a crash fails the test instead of the suite."""
    crash_reports = folder / "usd-crash-reports"
    crash_reports.mkdir(exist_ok=True)
    return subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "--no-cache", *args],
        capture_output=True,
        text=True,
        cwd=folder,
        env={**os.environ, "TMPDIR": str(crash_reports)},
        timeout=300,
    )


#: The flattened layer's documentation when the bytes above were found. Flatten
#: writes the root layer's path into it, so a fixed text keeps the crate's bytes
#: the same wherever the repository is checked out.
FLATTENED_DOC = (
    "A clean shot: a small set, a camera, RenderSettings, two products and six RenderVars.\n\n"
    "Generated from Composed Stage of root layer /work/wt-i13/examples/clean_shot/shot.usda\n"
)


def _shot_crate(folder: Path) -> bytes:
    stage = Usd.Stage.Open(str(REPO / "examples" / "clean_shot" / "shot.usda"))
    path = folder / "source.usdc"
    flattened = stage.Flatten()
    flattened.documentation = FLATTENED_DOC
    flattened.Export(str(path))
    data = path.read_bytes()
    path.unlink()
    return data


@pytest.mark.parametrize(
    "where",
    [["--jobs", "1", "--timeout", "0"], ["--jobs", "2"]],
    ids=["in-process", "workers"],
)
@pytest.mark.parametrize("full", [False, True], ids=["fast-path", "full-composition"])
def test_corrupt_crates_in_one_run_are_st001_and_the_others_are_linted(
    tmp_path: Path, full: bool, where: list[str]
) -> None:
    """In-process and in workers alike, without a crash: the spec types are
    read from the crate's bytes before any rule reads a property stack."""
    data = _shot_crate(tmp_path)
    if Usd.GetVersion() != (0, 26, 11):
        pytest.skip("another usd-core writes another crate layout; the bytes are elsewhere")
    assert len(data) == SHOT_CRATE_SIZE  # the crate the offsets were found in
    for offset in FLIPS:
        flipped = bytearray(data)
        flipped[offset] ^= 0xFF
        (tmp_path / f"flip{offset}.usdc").write_bytes(flipped)
    (tmp_path / "control.usda").write_text(CONTROL)
    extra = ["--full-composition"] if full else []
    names = [f"flip{offset}.usdc" for offset in FLIPS]
    result = lint(tmp_path, "--format", "json", *where, *extra, *names, "control.usda")
    assert (result.returncode, result.stderr) == (1, "")
    files = {f["file"]: f for f in json.loads(result.stdout)["files"]}
    for offset, message in FLIPS.items():
        entry = files[f"flip{offset}.usdc"]
        assert entry["status"] == "linted"
        assert [(f["code"], f["message"]) for f in entry["findings"]] == [("ST001", message)]
    assert "SE003" in {f["code"] for f in files["control.usda"]["findings"]}


@pytest.mark.parametrize("arc", ["references", "subLayers"])
def test_a_crate_naming_a_variant_with_no_name_through_an_arc_survives_in_process(
    tmp_path: Path, arc: str
) -> None:
    """usd-core writes a variant named "" into a crate from text that names
    one; Sdf's Traverse recurses on it without end (the fast path walked every
    reachable crate that way: the process died). Composing it is fine."""
    (tmp_path / "source.usda").write_text(EMPTY_VARIANT_NAME)
    Sdf.Layer.FindOrOpen(str(tmp_path / "source.usda")).Export(str(tmp_path / "variant.usdc"))
    if arc == "references":
        shot = '#usda 1.0\ndef "Asset" (\n    references = @./variant.usdc@\n)\n{\n}\n'
    else:
        shot = "#usda 1.0\n(\n    subLayers = [@./variant.usdc@]\n)\n"
    (tmp_path / "shot.usda").write_text(shot)
    (tmp_path / "control.usda").write_text(CONTROL)
    in_process = ("--format", "json", "--jobs", "1", "--timeout", "0")
    fast = lint(tmp_path, *in_process, "shot.usda", "control.usda")
    full = lint(tmp_path, *in_process, "--full-composition", "shot.usda", "control.usda")
    assert (fast.returncode, fast.stderr) == (1, "")
    assert fast.stdout == full.stdout
    files = {f["file"]: f for f in json.loads(fast.stdout)["files"]}
    assert files["shot.usda"]["status"] == "linted"
    assert "SE003" in {f["code"] for f in files["control.usda"]["findings"]}


def test_an_unexpected_engine_failure_is_one_line() -> None:
    """USD's exceptions span lines ("\\n\\tError in ..."): the report does not."""

    class Failing:
        raise_errors = False

        def lint_path(self, path: str, *, full_composition: bool = False) -> None:
            raise RuntimeError("\n\tError in 'Somewhere' at line 1 : 'what'\n")

    result = lint_one(Failing(), "shot.usda")
    assert (
        result.error
        == "shot.usda: internal error: RuntimeError: Error in 'Somewhere' at line 1 : 'what'"
    )


@pytest.mark.parametrize("retry", [False, True], ids=["first-lint", "retry"])
def test_only_the_retry_after_a_crash_walks_a_crates_specs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, retry: bool
) -> None:
    """On every path a crate's spec types are read from its bytes before the
    rules run (layers/crate.py); walking every spec through Sdf costs about
    as much as opening the layer, and is left to the retry after a crash
    (full_composition), which may meet what the types do not show."""
    from usdrender_lint.engine import linter as engine_linter
    from usdrender_lint.engine import partial
    from usdrender_lint.registry import build_registry

    walked: list[str] = []
    real = partial._Specs.check
    monkeypatch.setattr(
        partial._Specs,
        "check",
        lambda specs, layer: walked.append(layer.identifier) or real(specs, layer),
    )
    path = tmp_path / "shot.usdc"
    path.write_bytes(_shot_crate(tmp_path))
    linter = engine_linter.Linter([rule() for rule in build_registry().rules])
    assert linter.lint_path(str(path), full_composition=retry).status == "linted"
    assert bool(walked) is retry


CORRUPT = 2985  # of FLIPS: a spec of no valid type


@pytest.mark.parametrize("how", ["supervised", "python-api", "in-process-retry"])
def test_a_spec_of_no_valid_type_is_st001_on_every_path(tmp_path: Path, how: str) -> None:
    """The lone file of a supervised command, the Python API (linting in the
    caller's process) and the pool's retry fully composed: the same finding,
    no crash (in-process and the pool: the test above)."""
    data = bytearray(_shot_crate(tmp_path))
    if Usd.GetVersion() != (0, 26, 11) or len(data) != SHOT_CRATE_SIZE:
        pytest.skip("another usd-core writes another crate layout; the bytes are elsewhere")
    data[CORRUPT] ^= 0xFF
    name = f"flip{CORRUPT}.usdc"
    (tmp_path / name).write_bytes(data)
    if how == "supervised":
        result = lint(tmp_path, "--format", "json", name)
        assert (result.returncode, result.stderr) == (1, "")
        findings = json.loads(result.stdout)["files"][0]["findings"]
        found = [(f["code"], f["message"]) for f in findings]
    else:
        script = (
            "import sys, usdrender_lint\n"
            "print(usdrender_lint.lint_file(sys.argv[1]).files[0].findings[0].message)"
            if how == "python-api"
            else "import sys\n"
            "from usdrender_lint.engine import Linter\n"
            "from usdrender_lint.testing import all_rules\n"
            "result = Linter(all_rules()).lint_path(sys.argv[1], full_composition=True)\n"
            "print(result.findings[0].message)"
        )
        ran = subprocess.run(
            [sys.executable, "-c", script, name],
            capture_output=True, text=True, cwd=tmp_path, timeout=300,
        )  # fmt: skip
        assert (ran.returncode, ran.stderr) == (0, "")
        found = [("ST001", ran.stdout.strip())]
    assert found == [("ST001", FLIPS[CORRUPT])]
