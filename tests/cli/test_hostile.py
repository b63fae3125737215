"""Hostile input: every bad file gets a clear one-line answer naming the file
and the cause, the right exit code, no traceback, and the other files in the
same run are still linted.

Each case is linted through the real command line together with a control
file whose finding (SE003) proves the run went on. The inputs are generated
here; no binary blob is committed.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import zipfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest
from cli_support import EMPTY_VARIANT_NAME, HANGS, run_cli_process, settings_crate
from click.testing import CliRunner, Result
from pxr import Sdf, Usd, UsdRender, Vt

from usdrender_lint.api import Diagnostic, Rule, Severity
from usdrender_lint.cli import cli
from usdrender_lint.engine import Linter
from usdrender_lint.engine.locate import MAX_MESSAGE_CHARS
from usdrender_lint.running import workers as execution

CONTROL = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Control"
    {
        uniform float4 dataWindowNDC = (1, 1, 0, 0)
    }
}
"""
SCOPE = '#usda 1.0\ndef Scope "World"\n{\n}\n'
INT32_MAX, INT32_MIN = 2**31 - 1, -(2**31)


@dataclass(frozen=True)
class Expect:
    """What one hostile input must give.

    ``error``: a tool error whose message (after the file name) matches;
    ``code`` and ``cause``: a finding of that code whose message matches;
    otherwise the file is linted (``codes`` must be among its findings).
    """

    error: str | None = None
    code: str | None = None
    cause: str | None = None
    codes: tuple[str, ...] = ()


def run_cli(*args: str) -> Result:
    result = CliRunner().invoke(cli, ["check", "--isolated", "--format", "json", *args])
    output = result.stdout + result.stderr
    assert "Traceback" not in output, output
    assert isinstance(result.exception, SystemExit | None), repr(result.exception)
    return result


def _files_by_name(result: Result | subprocess.CompletedProcess) -> dict[str, dict]:
    return {entry["file"]: entry for entry in json.loads(result.stdout)["files"]}


# -- the inputs ---------------------------------------------------------------------


def _text(name: str, text: str) -> Callable[[Path], str]:
    def build(folder: Path) -> str:
        path = folder / name
        path.write_text(text, encoding="utf-8")
        return str(path)

    return build


def _bytes(name: str, data: bytes) -> Callable[[Path], str]:
    def build(folder: Path) -> str:
        path = folder / name
        path.write_bytes(data)
        return str(path)

    return build


def _crate_bytes(folder: Path) -> bytes:
    layer = Sdf.Layer.CreateNew(str(folder / "source.usdc"))
    stage = Usd.Stage.Open(layer)
    UsdRender.Settings.Define(stage, "/Render/Settings")
    layer.Save()
    data = (folder / "source.usdc").read_bytes()
    (folder / "source.usdc").unlink()
    return data


def truncated_usdc(folder: Path) -> str:
    path = folder / "truncated.usdc"
    data = _crate_bytes(folder)
    path.write_bytes(data[: len(data) // 2])
    return str(path)


def corrupt_usdz(folder: Path) -> str:
    path = folder / "corrupt.usdz"
    path.write_bytes(b"PK\x03\x04" + bytes(range(256)) * 4)
    return str(path)


def usdz_without_layer(folder: Path) -> str:
    path = folder / "notes.usdz"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as archive:
        archive.writestr("notes.txt", "not a layer")
    return str(path)


def symlink_loop(folder: Path) -> str:
    """A folder holding a link to itself and two .usda links to each other."""
    tree = folder / "loop"
    tree.mkdir()
    (tree / "self").symlink_to(tree, target_is_directory=True)
    (tree / "a.usda").symlink_to(tree / "b.usda")
    (tree / "b.usda").symlink_to(tree / "a.usda")
    return str(tree)


def sublayer_cycle(folder: Path) -> str:
    (folder / "cycle_b.usda").write_text("#usda 1.0\n(\n    subLayers = [@./cycle_a.usda@]\n)\n")
    path = folder / "cycle_a.usda"
    path.write_text(
        "#usda 1.0\n(\n    subLayers = [@./cycle_b.usda@]\n)\n"
        'def Scope "Render"\n{\n    def RenderSettings "S"\n    {\n    }\n}\n'
    )
    return str(path)


def deep_hierarchy(folder: Path) -> str:
    depth = 1000
    opening = "".join(f'def Scope "P{i}"\n{{\n' for i in range(depth))
    settings = 'def RenderSettings "S"\n{\n    uniform float4 dataWindowNDC = (1, 1, 0, 0)\n}\n'
    path = folder / "deep.usda"
    path.write_text("#usda 1.0\n" + opening + settings + "}\n" * depth)
    return str(path)


def huge_array(folder: Path) -> str:
    """10 million elements on a render prim (crate: the text would be 100 MB)."""
    path = folder / "huge.usdc"
    layer = Sdf.Layer.CreateNew(str(path))
    stage = Usd.Stage.Open(layer)
    settings = UsdRender.Settings.Define(stage, "/Render/Settings")
    big = settings.GetPrim().CreateAttribute("user:weights", Sdf.ValueTypeNames.FloatArray)
    big.Set(Vt.FloatArray(10_000_000))
    layer.Save()
    return str(path)


def non_finite(value: str) -> Callable[[Path], str]:
    """``value`` (nan, inf, -inf) in every float the rules read, at Default
    and in time samples."""
    f2, f4 = f"({value}, {value})", f"({value}, {value}, {value}, {value})"
    camera_floats = [
        "horizontalAperture",
        "verticalAperture",
        "horizontalApertureOffset",
        "verticalApertureOffset",
        "focalLength",
        "fStop",
        "focusDistance",
    ]
    camera = "\n".join(
        f"        float {name} = {value}\n        float {name}.timeSamples = {{ 1: {value} }}"
        for name in camera_floats
    )
    text = f"""#usda 1.0
def Scope "Render"
{{
    def Camera "Cam"
    {{
{camera}
        float2 clippingRange = {f2}
        float2 clippingRange.timeSamples = {{ 1: {f2} }}
        double shutter:open = {value}
        double shutter:close = {value}
        float exposure = {value}
    }}
    def RenderSettings "S"
    {{
        rel camera = </Render/Cam>
        rel products = </Render/P>
        uniform float pixelAspectRatio = {value}
        uniform float4 dataWindowNDC = {f4}
    }}
    def RenderProduct "P"
    {{
        uniform float pixelAspectRatio = {value}
        uniform float4 dataWindowNDC = {f4}
        rel orderedVars = </Render/V>
    }}
    def RenderVar "V"
    {{
        uniform string sourceName = "Ci"
    }}
}}
"""
    name = {"nan": "nan", "inf": "inf", "-inf": "neg_inf"}[value]
    return _text(f"non_finite_{name}.usda", text)


def int32_resolution(x: int, y: int, name: str) -> Callable[[Path], str]:
    return _text(
        f"resolution_{name}.usda",
        f"""#usda 1.0
def Scope "Render"
{{
    def Camera "Cam"
    {{
    }}
    def RenderSettings "S"
    {{
        rel camera = </Render/Cam>
        uniform int2 resolution = ({x}, {y})
        uniform float4 dataWindowNDC = (0, 0, 1, 1)
    }}
}}
""",
    )


FORWARDING_CYCLE = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "S"
    {
        rel camera = </Render/S.hop>
        rel hop = </Render/S.camera>
        rel products = </Render/P>
    }
    def RenderProduct "P"
    {
    }
}
"""

#: A common slip: a relationship written as a string attribute. Pcp then
#: refuses to compose targets for the name ("... is not a relationship").
RELATIONSHIPS_AS_ATTRIBUTES = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "S"
    {
        string camera = "/World/Cam"
        token products = "/Render/P"
    }
    def RenderProduct "P"
    {
        token camera = "/World/Cam"
    }
    def RenderPass "Pass"
    {
        string renderSource = "/Render/S"
        string inputPasses = "/Render/Pass"
    }
}
def Camera "Cam"
{
}
"""

#: The same slip on a product's orderedVars and a pass's collection targets.
VAR_AND_COLLECTION_RELATIONSHIPS_AS_ATTRIBUTES = """#usda 1.0
def Scope "Render"
{
    def RenderProduct "P"
    {
        string orderedVars = "/Render/V"
    }
    def RenderPass "Pass"
    {
        string collection:matte:includes = "/X"
        string collection:matte:excludes = "/X"
    }
}
"""

#: usda takes ``<...>`` as the value of an attribute of any type; Python reads
#: back an Sdf.Path where rules expect a token, string or number.
PATH_VALUES = """#usda 1.0
def Scope "Render"
{
    def RenderVar "V"
    {
        uniform token sourceType = <Render/Relative>
        uniform string sourceName = </X>
        uniform token dataType = </Y>
    }
    def RenderSettings "S"
    {
        rel camera = </Render/Cam>
        uniform float pixelAspectRatio = </Z>
        uniform token aspectRatioConformPolicy = </W>
        uniform token renderingColorSpace = </V>
    }
    def Camera "Cam"
    {
        float horizontalAperture = 36
        float horizontalAperture.timeSamples = {
            1: 30,
            10: </X>,
        }
        float focalLength.timeSamples = {
            1: </Y>,
        }
        float2 clippingRange = </Z>
    }
}
"""

#: The reverse slip: attributes written as relationships.
ATTRIBUTES_AS_RELATIONSHIPS = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "S"
    {
        rel dataWindowNDC = </X>
        rel pixelAspectRatio
    }
    def RenderProduct "P"
    {
        rel productName = </Z>
    }
    def RenderVar "V"
    {
        rel sourceName = </Z>
        rel sourceType = </Z>
    }
    def RenderPass "Pass"
    {
        rel passType = </Z>
        rel collection:renderVisibility:includeRoot = </Z>
    }
}
"""

#: pixelAspectRatio, dataWindowNDC, aperture/focal length, clipping range.
NON_FINITE_CODES = ("SE002", "SE003", "CA005", "CA009")

EMPTY = r"^the file is empty \(0 bytes\): it holds no USD layer$"

CASES: dict[str, tuple[Callable[[Path], str], Expect]] = {
    "missing-path": (lambda folder: str(folder / "missing.usda"), Expect(error="no such file")),
    "empty-file": (_text("empty.usda", ""), Expect(code="ST001", cause="not a valid usda layer")),
    # USD said "bad arguments to mmap()" and "Failed to open layer" for these.
    "empty-usdc": (_text("empty.usdc", ""), Expect(code="ST001", cause=EMPTY)),
    "empty-usd": (_text("empty.usd", ""), Expect(code="ST001", cause=EMPTY)),
    "binary-named-usda": (
        _bytes("binary.usda", bytes(range(256)) * 8),
        Expect(code="ST001", cause="not a valid usda layer"),
    ),
    "text-named-usdc": (
        _text("text.usdc", SCOPE * 10),
        Expect(code="ST001", cause="crate bootstrap section corrupt"),
    ),
    "truncated-usdc": (truncated_usdc, Expect(code="ST001", cause="possibly truncated")),
    "corrupt-usdz": (corrupt_usdz, Expect(code="ST001", cause="not a zip archive")),
    "usdz-without-layer": (usdz_without_layer, Expect(code="ST001", cause="not a USD layer")),
    "syntax-error-last-line": (
        # One closing brace too many, on the last line (8).
        _text("syntax.usda", SCOPE + 'def Scope "Broken"\n{\n}\n}\n'),
        Expect(code="ST001", cause=r"syntax\.usda:8:1: "),
    ),
    "invalid-utf8": (
        _bytes("utf8.usda", b'#usda 1.0\ndef Scope "A"\n{\n    string s = "caf\xe9"\n}\n'),
        Expect(code="ST001", cause=r"utf8\.usda:4:20: invalid UTF-8 \(byte 0xe9\)"),
    ),
    "symlink-loop-folder": (symlink_loop, Expect(error="a broken or looping symbolic link")),
    # GetForwardedTargets stops at the cycle: no camera (CA001), no hang.
    "relationship-forwarding-cycle": (
        _text("forwarding.usda", FORWARDING_CYCLE),
        Expect(codes=("CA001",)),
    ),
    # No composed products and no camera: a settings alone, so no CA001 (R2-2).
    "relationships-authored-as-attributes": (
        _text("rel_as_attr.usda", RELATIONSHIPS_AS_ATTRIBUTES),
        Expect(codes=("SE015",)),
    ),
    "var-and-collection-relationships-authored-as-attributes": (
        _text("rel_as_attr2.usda", VAR_AND_COLLECTION_RELATIONSHIPS_AS_ATTRIBUTES),
        Expect(codes=("PR004",)),
    ),
    "path-values-in-typed-attributes": (
        _text("path_values.usda", PATH_VALUES),
        Expect(codes=("VA001",)),
    ),
    "attributes-authored-as-relationships": (
        _text("attr_as_rel.usda", ATTRIBUTES_AS_RELATIONSHIPS),
        Expect(codes=("PR001", "VA001")),
    ),
    "deep-hierarchy": (deep_hierarchy, Expect(codes=("SE003",))),
    "huge-array": (huge_array, Expect()),
    "nan": (non_finite("nan"), Expect(codes=NON_FINITE_CODES)),
    "inf": (non_finite("inf"), Expect(codes=NON_FINITE_CODES)),
    "neg-inf": (non_finite("-inf"), Expect(codes=NON_FINITE_CODES)),
    "resolution-int32-max": (
        int32_resolution(INT32_MAX, INT32_MAX, "max"),
        Expect(codes=("CA006",)),
    ),
    "resolution-int32-min": (
        int32_resolution(INT32_MIN, INT32_MIN, "min"),
        Expect(codes=("SE001",)),
    ),
    "resolution-int32-mixed": (
        int32_resolution(INT32_MAX, INT32_MIN, "mixed"),
        Expect(codes=("SE001",)),
    ),
    "spaces-and-non-ascii-name": (
        _text("plan de tournage é 渲染.usda", CONTROL),
        Expect(codes=("SE003",)),
    ),
}


def _check_case(path: str, expect: Expect, result: Result, files: dict[str, dict]) -> None:
    errors = [line for line in result.stderr.splitlines() if line]
    if expect.error is not None:
        failed = [e for e in files.values() if e["status"] == "error"]
        assert failed
        for entry in failed:
            assert entry["file"].startswith(path)
            assert entry["error"] == f"{entry['file']}: {expect.error}"
        assert errors == [f"usdrender-lint: error: {e['error']}" for e in failed]
        assert result.exit_code == 2
        return
    assert not errors, result.stderr
    entry = files[path]
    assert entry["status"] == "linted"
    codes = {f["code"] for f in entry["findings"]}
    assert "UL000" not in codes, [f["message"] for f in entry["findings"]]
    if expect.code is not None:
        # The position USD gives is the finding's (layer:line:col), not in its message.
        causes = [_positioned(f) for f in entry["findings"] if f["code"] == expect.code]
        assert any(re.search(expect.cause, m) for m in causes), causes
        assert all(f["file"] == path for f in entry["findings"])
    assert set(expect.codes) <= codes, codes
    assert result.exit_code == 1  # the control file's SE003 at least


def _positioned(finding: dict) -> str:
    if finding["line"] is None:
        return finding["message"]
    column = f"{finding['column']}:" if finding["column"] else ""
    return f"{finding['layer']}:{finding['line']}:{column} {finding['message']}"


@pytest.mark.parametrize("case", list(CASES))
def test_hostile_input_gets_a_clear_answer_and_the_run_goes_on(tmp_path: Path, case: str) -> None:
    build, expect = CASES[case]
    path = build(tmp_path)
    control = _text("control.usda", CONTROL)(tmp_path)
    result = run_cli("--jobs", "1", "--timeout", "0", path, control)
    files = _files_by_name(result)
    assert "SE003" in {f["code"] for f in files[control]["findings"]}, "control not linted"
    _check_case(path, expect, result, files)


def test_every_hostile_input_in_one_parallel_run(tmp_path: Path) -> None:
    """All cases at once with the default worker pool and time limit: one
    answer per input, the same as one file at a time, exit 2 (a missing path)."""
    paths = {case: build(tmp_path / case) for case, (build, _) in _prepared(tmp_path)}
    control = _text("control.usda", CONTROL)(tmp_path)
    result = run_cli(*paths.values(), control)
    assert result.exit_code == 2
    files = _files_by_name(result)
    assert "SE003" in {f["code"] for f in files[control]["findings"]}
    errors = [line for line in result.stderr.splitlines() if line]
    assert errors == [
        f"usdrender-lint: error: {paths['missing-path']}: no such file",
        f"usdrender-lint: error: {paths['symlink-loop-folder']}/a.usda: "
        "a broken or looping symbolic link",
        f"usdrender-lint: error: {paths['symlink-loop-folder']}/b.usda: "
        "a broken or looping symbolic link",
    ]
    serial = run_cli("--jobs", "1", "--timeout", "0", *paths.values(), control)
    assert serial.stdout == result.stdout


def test_a_symlink_loop_is_reported_where_configuration_is_searched(tmp_path: Path) -> None:
    """Without --isolated each file's configuration is searched from its real
    folder: a looping link is still its own one-line error, the others linted."""
    tree = symlink_loop(tmp_path)
    control = _text("control.usda", CONTROL)(Path(tree))
    result = CliRunner().invoke(cli, ["check", "--no-cache", "--format", "json", tree])
    assert "Traceback" not in result.output + result.stderr, result.stderr
    assert result.exit_code == 2, result.stderr
    files = _files_by_name(result)
    assert "SE003" in {f["code"] for f in files[control]["findings"]}
    assert files[f"{tree}/a.usda"]["error"] == f"{tree}/a.usda: a broken or looping symbolic link"


def _prepared(folder: Path):
    for case, entry in CASES.items():
        (folder / case).mkdir()
        yield case, entry


@pytest.mark.parametrize("case", ["sublayer-cycle", "reference-to-missing-file"])
def test_composition_errors_are_st002(tmp_path: Path, case: str) -> None:
    if case == "sublayer-cycle":
        path, cause = sublayer_cycle(tmp_path), "has cycles"
    else:
        path, cause = (
            _text(
                "reference.usda",
                """#usda 1.0
def Scope "Render"
{
    def RenderSettings "S" (
        references = @./facility/missing.usda@</Render/S>
    )
    {
    }
}
""",
            )(tmp_path),
            "Could not open asset",
        )
    control = _text("control.usda", CONTROL)(tmp_path)
    result = run_cli("--jobs", "1", "--timeout", "0", path, control)
    files = _files_by_name(result)
    assert files[path]["status"] == "linted"
    assert "SE003" in {f["code"] for f in files[control]["findings"]}
    assert not result.stderr
    messages = [f["message"] for f in files[path]["findings"] if f["code"] == "ST002"]
    assert any(cause in m for m in messages), messages


def test_a_hung_read_times_out_and_the_rest_are_linted(tmp_path: Path) -> None:
    """A sublayer that blocks USD forever (cli_support.HANGING_SUBLAYER)."""
    if not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs on this platform")
    os.mkfifo(tmp_path / "pipe.usda")
    path = _text("hangs.usda", HANGS)(tmp_path)
    control = _text("control.usda", CONTROL)(tmp_path)
    result = run_cli("--timeout", "2", path, control)
    assert result.exit_code == 2
    assert result.stderr == (
        f"usdrender-lint: error: {path}: timed out after 2 s while USD opened the stage "
        "(raise --timeout, or 0 for no limit)\n"
    )
    assert "SE003" in {f["code"] for f in _files_by_name(result)[control]["findings"]}


def test_a_fifo_given_as_a_file_is_refused_not_read(tmp_path: Path) -> None:
    if not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs on this platform")
    os.mkfifo(tmp_path / "pipe.usda")
    result = run_cli("--jobs", "1", "--timeout", "0", str(tmp_path / "pipe.usda"))
    assert result.exit_code == 2
    assert result.stderr == f"usdrender-lint: error: {tmp_path / 'pipe.usda'}: not a regular file\n"


def test_text_report_names_non_ascii_files(tmp_path: Path) -> None:
    folder = tmp_path / "dossier été"
    folder.mkdir()
    _text("plan 渲染.usda", CONTROL)(folder)
    _text("cassé.usda", '#usda 1.0\ndef Scope "X" {\n')(folder)
    result = CliRunner().invoke(cli, ["check", "--isolated", "--jobs", "1", str(folder)])
    assert result.exit_code == 1
    assert "Traceback" not in result.stdout + result.stderr
    assert "plan 渲染.usda" in result.stdout and "cassé.usda" in result.stdout


class QuoteEverything(Rule):
    """Test-only rule: quotes an array attribute in full.

    ## What it does
    Reports each RenderSettings with every element of ``user:weights``.
    """

    code = "TX902"
    name = "test-quote-everything"
    severity = Severity.INFO
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim, ctx):
        values = prim.GetAttribute("user:weights").Get()
        yield Diagnostic(message=f"weights {list(values)}", at=prim)


def test_a_rule_quoting_a_huge_array_gives_a_bounded_message(tmp_path: Path) -> None:
    path = tmp_path / "weights.usda"
    path.write_text(
        '#usda 1.0\ndef RenderSettings "S"\n{\n'
        f"    float[] user:weights = [{', '.join(['0.5'] * 100_000)}]\n}}\n"
    )
    [finding] = Linter([QuoteEverything()], raise_errors=True).lint_path(str(path)).findings
    assert finding.message.startswith("weights [0.5, 0.5")
    assert len(finding.message) < MAX_MESSAGE_CHARS + 40
    assert finding.message.endswith(
        f"({len('weights []') + 100_000 * 5 - 2 - MAX_MESSAGE_CHARS} more characters)"
    )


def test_a_layer_that_aborts_usd_costs_only_itself(tmp_path: Path) -> None:
    """A variant named "": usd-core 26.11 opens it, but some Sdf layer walks
    (``GetCompositionAssetDependencies``) abort the process with a fatal error.
    Workers contain that: one clean line, the other files linted."""
    path = _text("empty_variant.usda", EMPTY_VARIANT_NAME)(tmp_path)
    control = _text("control.usda", CONTROL)(tmp_path)
    result = run_cli_process(tmp_path, "--jobs", "2", path, control)
    files = _files_by_name(result)
    assert "SE003" in {f["code"] for f in files[control]["findings"]}
    lines = result.stderr.splitlines()
    assert all(line.startswith("usdrender-lint: error: ") for line in lines), result.stderr
    if files[path]["status"] == "error":  # until the engine avoids the aborting call
        assert lines == [
            f"usdrender-lint: error: {path}: the linter process crashed while reading it "
            "(signal SIGABRT: USD fatal error: Dereferenced an invalid SdfVariantSetSpec)"
        ]
        assert result.returncode == 2
    else:
        assert not lines


def test_a_crate_that_makes_usd_allocate_without_end_is_cut_short(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """One flipped byte in a .usdc: usd-core 26.11 then allocates memory
    until the machine runs out (8.8 GB in 8 s here). Workers have a memory cap,
    so the allocation fails at once and USD reports it as an open error."""
    data = bytearray(settings_crate(tmp_path / "settings.usdc"))
    if len(data) != 1219:
        pytest.skip("usd-core writes another crate layout; the corrupt byte is elsewhere")
    data[540] = 33
    path = tmp_path / "corrupt.usdc"
    path.write_bytes(data)
    control = _text("control.usda", CONTROL)(tmp_path)
    # The cap a 4 GiB machine with two workers gets (the default depends on the host).
    monkeypatch.setattr(execution, "worker_memory_limit", lambda workers: 2 << 30)
    # A short limit: were the cap to fail, the worker is killed before the host suffers.
    result = run_cli("--jobs", "2", "--timeout", "10", str(path), control)
    files = _files_by_name(result)
    # Refused before USD reads it (layers/crate.py); USD said
    # "Encountered: std::bad_alloc" once the cap stopped it.
    assert [f["message"] for f in files[str(path)]["findings"]] == [
        "the crate's FIELDS section states 553,648,154 items in 217 bytes, more than they can "
        "hold: the file is corrupt"
    ]
    assert "SE003" in {f["code"] for f in files[control]["findings"]}
    assert not result.stderr


def test_workers_share_the_memory() -> None:
    one, four = execution.worker_memory_limit(1), execution.worker_memory_limit(4)
    assert one is not None and four is not None
    assert execution.MIN_WORKER_MEMORY <= four <= one


def test_a_crate_with_names_that_are_not_utf8_is_st001(tmp_path: Path) -> None:
    """One flipped byte in a .usdc's token table: USD composes the stage, but
    every Python read of the name raises UnicodeDecodeError."""
    data = bytearray(settings_crate(tmp_path / "settings.usdc"))
    if len(data) != 1219:
        pytest.skip("usd-core writes another crate layout; the corrupt byte is elsewhere")
    data[374] = 0x81
    path = tmp_path / "names.usdc"
    path.write_bytes(data)
    control = _text("control.usda", CONTROL)(tmp_path)
    result = run_cli("--jobs", "1", "--timeout", "0", str(path), control)
    files = _files_by_name(result)
    assert [(f["code"], f["message"]) for f in files[str(path)]["findings"]] == [
        (
            "ST001",
            "the file holds a name or string that is not valid UTF-8 (byte 0x81); USD reads "
            "it, but nothing in it can be checked: the file is probably corrupt",
        )
    ]
    assert "SE003" in {f["code"] for f in files[control]["findings"]}
    assert result.exit_code == 1 and not result.stderr


def test_a_crate_value_found_corrupt_while_a_rule_reads_it_is_st001(tmp_path: Path) -> None:
    """USD unpacks crate values lazily: this one is found corrupt only when a
    rule reads it. That is the file's problem (ST001), not the rule's (UL000)."""
    data = bytearray(settings_crate(tmp_path / "settings.usdc"))
    if len(data) != 1219:
        pytest.skip("usd-core writes another crate layout; the corrupt byte is elsewhere")
    data[215] = 49
    path = tmp_path / "value.usdc"
    path.write_bytes(data)
    result = run_cli("--jobs", "1", "--timeout", "0", str(path))
    [finding] = _files_by_name(result)[str(path)]["findings"]
    assert (finding["code"], finding["message"]) == (
        "ST001",
        f"Corrupt asset <{path}>: exception thrown unpacking a value, returning an empty VtValue",
    )
    assert result.exit_code == 1 and not result.stderr
