"""Option values out of range are usage errors (exit 2, one clear line), on the
command line, in the configuration file and through the Python API."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

import usdrender_lint
from usdrender_lint.cli import cli
from usdrender_lint.config import MAX_JOBS, MAX_TIMEOUT, MAX_VARIANT_COMBINATIONS, ConfigError
from usdrender_lint.running.pipeline import Request, RequestError, run

REPO = Path(__file__).resolve().parents[2]
CLEAN = str(REPO / "examples" / "clean_shot" / "shot.usda")


def check(*args: str):
    return CliRunner().invoke(cli, ["check", "--isolated", *args])


@pytest.mark.parametrize(
    ("option", "value"),
    [
        ("--timeout", "nan"),
        ("--timeout", "inf"),
        ("--timeout", "-inf"),
        ("--timeout", "1e308"),
        ("--timeout", "-1"),
        ("--timeout", str(MAX_TIMEOUT + 1)),
        ("--jobs", "0"),
        ("--jobs", "-3"),
        ("--jobs", str(MAX_JOBS + 1)),
        ("--max-variant-combinations", "0"),
        ("--max-variant-combinations", str(10**18)),
        ("--max-variant-combinations", str(MAX_VARIANT_COMBINATIONS + 1)),
    ],
)
def test_an_out_of_range_value_is_a_usage_error(option: str, value: str) -> None:
    result = check(option, value, CLEAN)
    assert result.exit_code == 2
    assert f"Invalid value for '{option}'" in result.stderr
    assert "Traceback" not in result.output and "internal error" not in result.output


@pytest.mark.parametrize(
    ("option", "value"), [("--timeout", "nan"), ("--timeout", "1e308"), ("--jobs", "0")]
)
def test_spec_checks_the_same_ranges(option: str, value: str) -> None:
    """spec takes check's --jobs and --timeout, with check's range checks."""
    result = CliRunner().invoke(cli, ["spec", "--isolated", option, value, CLEAN])
    assert result.exit_code == 2
    assert f"Invalid value for '{option}'" in result.stderr
    assert "Traceback" not in result.output and "internal error" not in result.output


@pytest.mark.parametrize(
    "args",
    [
        ("--timeout", "0"),
        ("--timeout", str(MAX_TIMEOUT)),
        ("--timeout", "0.5"),
        ("--jobs", "1"),
        ("--variants", "--max-variant-combinations", str(MAX_VARIANT_COMBINATIONS)),
    ],
)
def test_the_bounds_themselves_are_accepted(args: tuple[str, ...]) -> None:
    assert check(*args, CLEAN).exit_code == 0


@pytest.mark.parametrize(
    "request_",
    [
        Request((CLEAN,), isolated=True, timeout=float("nan")),
        Request((CLEAN,), isolated=True, timeout=1e308),
        Request((CLEAN,), isolated=True, jobs=0),
        Request((CLEAN,), isolated=True, max_variant_combinations=10**9),
    ],
)
def test_the_pipeline_checks_them_too(request_: Request) -> None:
    with pytest.raises(RequestError, match="must be"):
        run(request_)


def test_the_python_api_checks_them() -> None:
    # The API's documented exception for a bad configuration.
    with pytest.raises(ConfigError, match="^argument max_variant_combinations must be"):
        usdrender_lint.lint_file(CLEAN, variants=True, max_variant_combinations=10**9)


def test_an_absurd_cap_in_the_config_file_is_a_config_error(tmp_path: Path) -> None:
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text(f"variants = true\nmax-variant-combinations = {10**12}\n")
    result = CliRunner().invoke(cli, ["check", "--config", str(config), CLEAN])
    assert result.exit_code == 2
    assert result.stderr == (
        f"usdrender-lint: error: {config}:2: 'max-variant-combinations' must be a whole number "
        f"from 1 to {MAX_VARIANT_COMBINATIONS}, got {10**12}\n"
    )
