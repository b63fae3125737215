"""Fuzz: mutate valid usda layers (delete, duplicate, swap and corrupt tokens,
values and brackets) and run the full rule set on whatever opens.

No exception may escape a rule or the engine (the linter re-raises rule
errors here), and no traceback may reach the user of the command line.
Binary (crate) layers get random byte flips and go through the worker pool,
since USD itself may hang or abort on them.

CI runs a few hundred examples, reproducibly; set
``USDRENDER_LINT_FUZZ_EXAMPLES=5000`` for a longer, randomised run.
"""

from __future__ import annotations

import json
import os
import random
import re
import tempfile
from pathlib import Path

import pytest
from cli_support import run_cli_process, settings_crate
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from usdrender_lint.cli import cli
from usdrender_lint.engine import Linter
from usdrender_lint.testing import all_rules

pytestmark = pytest.mark.heavy(seconds=19)

RULE_FIXTURES = Path(__file__).parents[1] / "rules"
_EXAMPLES_ENV = os.environ.get("USDRENDER_LINT_FUZZ_EXAMPLES")
EXAMPLES = int(_EXAMPLES_ENV or 500)
FUZZ = settings(
    max_examples=EXAMPLES,
    deadline=None,
    database=None,  # never write a .hypothesis folder into the checkout
    derandomize=_EXAMPLES_ENV is None,  # CI: the same examples every run
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

BUILT_IN_SEEDS = (
    """#usda 1.0
(
    renderSettingsPrimPath = "/Render/Settings"
)
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel camera = </World/Cam>
        rel products = [</Render/Beauty>, </Render/Deep>]
        uniform int2 resolution = (1920, 1080)
        uniform float pixelAspectRatio = 1
        uniform float4 dataWindowNDC = (0, 0, 1, 1)
        uniform token aspectRatioConformPolicy = "expandAperture"
        uniform token[] includedPurposes = ["default", "render"]
        uniform token[] materialBindingPurposes = ["full", ""]
        uniform token renderingColorSpace = "lin_rec709_scene"
    }
    def RenderProduct "Beauty"
    {
        token productName = "beauty.exr"
        rel orderedVars = [</Render/Vars/color>, </Render/Vars/alpha>]
    }
    def RenderProduct "Deep"
    {
        token productName.timeSamples = { 1: "deep.1.exr", 2: "deep.2.exr" }
        uniform token productType = "deepRaster"
        rel orderedVars = </Render/Vars/color>
    }
    def Scope "Vars"
    {
        def RenderVar "color"
        {
            uniform string sourceName = "C<.>*[LO]"
            uniform token sourceType = "lpe"
        }
        def RenderVar "alpha"
        {
            uniform token dataType = "float"
            uniform string sourceName = "a"
        }
    }
    def RenderPass "Pass"
    {
        rel renderSource = </Render/Settings>
        rel inputPasses = </Render/Pass>
        uniform token passType = "prman"
        uniform asset fileName = @./pass.usda@
        uniform bool collection:renderVisibility:includeRoot = false
        uniform pathExpression collection:renderVisibility:membershipExpression = "/World//"
    }
}
def Xform "World"
{
    def Camera "Cam"
    {
        float focalLength = 35
        float focalLength.timeSamples = { 1: 35, 10: 50 }
        float2 clippingRange = (0.1, 10000)
        float horizontalAperture = 36
        float verticalAperture = 24
        float fStop = 2.8
        double shutter:open = -0.25
        double shutter:close = 0.25
        token purpose = "render"
    }
}
""",
)


def _seeds() -> list[str]:
    fixtures = sorted(RULE_FIXTURES.glob("*/*.usda"))
    return [*BUILT_IN_SEEDS, *(p.read_text(encoding="utf-8") for p in fixtures)]


SEEDS = _seeds()
_TOKEN = re.compile(
    r'"""[\s\S]*?"""|"(?:\\.|[^"\\\n])*"|@[^@\n]*@|<[^>\n]*>|[-+]?\d[\w.+-]*|[A-Za-z_][\w:.]*'
    r"|\s+|."
)
#: Replacement tokens that probe parsing, types, limits and composition.
HOSTILE_TOKENS = (
    "nan",
    "inf",
    "-inf",
    "1e400",
    "-0",
    "0",
    "-1",
    "2147483647",
    "2147483648",
    "-2147483649",
    "9" * 40,
    '""',
    '"\\u0000"',
    '"é渲染"',
    "[",
    "]",
    "(",
    ")",
    "{",
    "}",
    "<",
    ">",
    "=",
    ",",
    "None",
    "</>",
    "</Render>",
    "</Render/Settings.camera>",
    "<../up>",
    "<Render/Relative>",
    "@./missing.usda@",
    "@@",
    "@./pass.usda@",
    "def",
    "over",
    "class",
    "rel",
    "uniform",
    "custom",
    "prepend",
    "delete",
    "token[]",
    "float4",
    "int2",
    "string",
    "asset",
    "bool",
    "RenderSettings",
    "RenderProduct",
    "RenderVar",
    "RenderPass",
    "Camera",
    "Scope",
    "timeSamples",
    "connect",
    "references",
    "payload",
    "inherits",
    "specializes",
    "subLayers",
    "variantSet",
    "variants",
    "kind",
    "instanceable",
    "active",
    "true",
    "false",
    # Text the report formats must escape, not interpret.
    '"[/]"',
    '"[bold red]x[/bold red]"',
    '"%s {0} \\\\"',
)

_mutation = st.one_of(
    st.tuples(st.just("delete"), st.integers(0, 10**6)),
    st.tuples(st.just("duplicate"), st.integers(0, 10**6)),
    st.tuples(st.just("swap"), st.integers(0, 10**6), st.integers(0, 10**6)),
    st.tuples(st.just("corrupt"), st.integers(0, 10**6), st.sampled_from(HOSTILE_TOKENS)),
    st.tuples(st.just("corrupt"), st.integers(0, 10**6), st.text(min_size=1, max_size=6)),
)


def mutate(seed: str, mutations: list[tuple]) -> str:
    """Apply token-level mutations (indices wrap) to a layer's text."""
    tokens = _TOKEN.findall(seed)
    # Mutate meaningful tokens only, so most mutations change the parse.
    for mutation in mutations:
        solid = [i for i, t in enumerate(tokens) if not t.isspace()]
        if not solid:
            break
        kind, at = mutation[0], solid[mutation[1] % len(solid)]
        if kind == "delete":
            del tokens[at]
        elif kind == "duplicate":
            tokens.insert(at, tokens[at])
        elif kind == "swap":
            other = solid[mutation[2] % len(solid)]
            tokens[at], tokens[other] = tokens[other], tokens[at]
        else:
            tokens[at] = mutation[2]
    return "".join(tokens)


LINTER = Linter(all_rules(), raise_errors=True)


def _lint_text(text: str) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "fuzz.usda")
        with open(path, "w", encoding="utf-8", errors="surrogatepass") as handle:
            handle.write(text)
        result = LINTER.lint_path(path)
        assert result.status == "linted", result.error


@FUZZ
@given(
    seed=st.sampled_from(SEEDS),
    mutations=st.lists(_mutation, min_size=1, max_size=6),
)
def test_no_rule_or_engine_raises_on_a_mutated_layer(seed: str, mutations: list[tuple]) -> None:
    _lint_text(mutate(seed, mutations))


@settings(FUZZ, max_examples=max(20, EXAMPLES // 10))
@given(
    seed=st.sampled_from(SEEDS),
    mutations=st.lists(_mutation, min_size=1, max_size=4),
    output_format=st.sampled_from(["text", "json", "sarif", "github"]),
)
def test_no_traceback_reaches_the_user(
    seed: str, mutations: list[tuple], output_format: str
) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "fuzz.usda")
        with open(path, "w", encoding="utf-8", errors="surrogatepass") as handle:
            handle.write(mutate(seed, mutations))
        result = CliRunner().invoke(
            cli,
            [
                "check",
                "--isolated",
                "--jobs",
                "1",
                "--timeout",
                "0",
                "--show-info",
                "--format",
                output_format,
                path,
            ],
        )
    assert result.exit_code in (0, 1), result.stdout + result.stderr
    assert isinstance(result.exception, SystemExit | None), repr(result.exception)
    assert "Traceback" not in result.stdout + result.stderr


def test_mutations_change_the_layer() -> None:
    seed = BUILT_IN_SEEDS[0]
    assert mutate(seed, [("delete", 0)]) != seed
    assert mutate(seed, [("corrupt", 3, "nan")]).count("nan") == 1
    swapped = mutate('#usda 1.0\ndef Scope "A" {\n}\n', [("swap", 0, 5)])
    assert swapped.startswith('"A"')


def test_bit_flipped_crates_each_get_one_answer() -> None:
    """Binary layers with a few random bytes changed. USD may reject them, hang,
    allocate without end or abort on them: through the worker pool every file
    still gets exactly one answer, and an error is one line naming the file."""
    count = max(40, EXAMPLES // 10)
    rng = random.Random(0 if _EXAMPLES_ENV is None else None)
    with tempfile.TemporaryDirectory() as folder:
        base = settings_crate(Path(folder) / "settings.usdc")
        files = []
        for index in range(count):
            data = bytearray(base)
            for _ in range(rng.randint(1, 4)):
                data[rng.randrange(len(data))] = rng.randrange(256)
            path = os.path.join(folder, f"flipped_{index:04d}.usdc")
            with open(path, "wb") as handle:
                handle.write(data)
            files.append(path)
        result = run_cli_process(Path(folder), "--jobs", "2", "--timeout", "10", *files)
    assert result.returncode in (1, 2)
    report = json.loads(result.stdout)
    assert [entry["file"] for entry in report["files"]] == files
    errors = [entry["error"] for entry in report["files"] if entry["status"] == "error"]
    assert result.stderr.splitlines() == [f"usdrender-lint: error: {e}" for e in errors]
    for entry in report["files"]:
        assert all("\n" not in f["message"] for f in entry["findings"])
