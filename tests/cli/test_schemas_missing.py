"""USD's schema registry without the rules' prim definitions: under ``ulimit -v``
about 1.1 GiB it warned that it could not open a plugin's generatedSchema.usda
and went on with empty definitions, and the lint ran on: every fallback value
None, rules raising (UL000) and findings wrong. Nothing is linted now: one line, exit 2.

USD's own ``USD_DISABLE_PRIM_DEFINITIONS_FOR_USDGENSCHEMA`` builds the registry
the same way (``pxr/usd/usd/schemaRegistry.cpp``): the tests' way to get one."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from usdrender_lint.engine import SchemasMissing
from usdrender_lint.running.address_space import schemas_missing

pytestmark = pytest.mark.heavy(seconds=6)

FIXTURES = Path(__file__).parents[1] / "rules" / "CA006_aspect_ratio_mismatch_implicit_conform"
SETTING = "USD_DISABLE_PRIM_DEFINITIONS_FOR_USDGENSCHEMA"
SAID = (
    "usdrender-lint: error: USD's schema registry has no prim definition for RenderSettings, "
    "RenderProduct, RenderVar, RenderPass, Camera ("
    f"{SETTING} is set, for usdGenSchema only: unset it); the rules would read no fallback "
    "values, so nothing was linted"
)


@pytest.mark.parametrize(
    "how",
    [
        ["--jobs", "2"],
        ["--jobs", "1", "--timeout", "0"],
        ["--diff"],
        ["--diff", "--jobs", "1", "--timeout", "0"],
        ["--cache-dir", "{cache}"],
        ["-"],
    ],
    ids=["workers", "in-process", "diff", "diff-in-process", "cached", "standard-input"],
)
def test_a_registry_without_the_prim_definitions_lints_nothing(
    tmp_path: Path, how: list[str]
) -> None:
    files = [str(FIXTURES / "fail_mismatch.usda"), str(FIXTURES / "pass_traps.usda")]
    how = [arg.format(cache=tmp_path / "cache") for arg in how]
    command = [sys.executable, "-m", "usdrender_lint", "check", "--isolated", *how]
    if "--cache-dir" in how:  # the files' results cached first: the lookup refuses too
        warm = subprocess.run([*command, *files], capture_output=True, timeout=120)
        assert warm.returncode == 1, warm.stderr
    else:
        command.append("--no-cache")
    given = Path(files[0]).read_text() if "-" in how else None
    done = subprocess.run(
        command if given is not None else [*command, *files],
        input=given,
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, SETTING: "1"},
    )
    # USD itself prints a banner of '#' lines naming the setting as it loads.
    said = [line for line in done.stderr.splitlines() if not line.startswith("#")]
    assert (done.returncode, done.stdout, said) == (2, "", [SAID]), done.stderr


def test_a_registry_that_could_not_read_the_schemas_names_the_address_space_limit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delenv(SETTING, raising=False)
    monkeypatch.setattr(
        "usdrender_lint.running.address_space.address_space_limit", lambda: 1100 << 20
    )
    assert schemas_missing(SchemasMissing(("RenderSettings", "Camera"))) == (
        "USD's schema registry has no prim definition for RenderSettings, Camera (USD could "
        "not read their schemas); the rules would read no fallback values, so nothing was "
        "linted; the address-space limit (ulimit -v) is 1100 MiB: raise it"
    )


def test_a_stage_a_host_opened_is_not_linted_either() -> None:
    # lint_stage (and the UsdValidation and Asset Validator plugins, which lint a host's
    # stage) never opened a file, so nothing asked the registry: it linted wrongly.
    script = (
        "import sys, usdrender_lint\n"
        "from usdrender_lint.config import ConfigError\n"
        "from pxr import Usd\n"
        "stage = Usd.Stage.Open(sys.argv[1])\n"
        "try:\n"
        "    usdrender_lint.lint_stage(stage)\n"
        "except ConfigError as exc:\n"
        "    print('refused:', exc)\n"
    )
    done = _api_script(script)
    assert done.stdout == f"refused: {SAID.removeprefix('usdrender-lint: error: ')}\n"


def test_the_api_raises_its_own_error_not_a_configuration_error() -> None:
    # ConfigError told the caller their configuration was wrong: the one
    # exception to catch is this process's USD's, still a ConfigError for the
    # except clauses written for it.
    script = (
        "import sys, usdrender_lint\n"
        "from usdrender_lint.config import ConfigError\n"
        "from pxr import Usd\n"
        "stage = Usd.Stage.Open(sys.argv[1])\n"
        "for call in (usdrender_lint.lint_file, usdrender_lint.lint_stage):\n"
        "    given = stage if call is usdrender_lint.lint_stage else sys.argv[1]\n"
        "    try:\n"
        "        call(given)\n"
        "    except Exception as exc:\n"
        "        assert exc.__class__ is usdrender_lint.SchemaRegistryError, repr(exc)\n"
        "        assert isinstance(exc, ConfigError) and exc.__cause__ is None\n"
        "        print(call.__name__, exc)\n"
    )
    done = _api_script(script)
    said = SAID.removeprefix("usdrender-lint: error: ")
    assert done.stdout == f"lint_file {said}\nlint_stage {said}\n"


def _api_script(script: str) -> subprocess.CompletedProcess[str]:
    """``script`` run on a stage whose render schemas this USD lacks (SETTING
    set), given the fixture's path; it must exit 0."""
    done = subprocess.run(
        [sys.executable, "-c", script, str(FIXTURES / "fail_mismatch.usda")],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, SETTING: "1"},
    )
    assert done.returncode == 0, done.stderr
    return done
