"""A lint leaves no reference cycles behind: what it read is freed as its
cache is dropped, not left for the cyclic garbage collector, whose collections
walk every young object (on a CI gate a cycle per render prim cost about 0.5 ms
a shot in collections, and kept each shot's answers alive until one ran)."""

from __future__ import annotations

import gc
from collections.abc import Iterator
from pathlib import Path

import pytest

import usdrender_lint
from usdrender_lint.api import Context, Rule, Severity, schemas
from usdrender_lint.api.resolve import PrimValues, prim_values
from usdrender_lint.engine import Linter

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SHOTS = sorted(EXAMPLES.glob("*/*.usda"))


@pytest.fixture
def garbage() -> Iterator[list[object]]:
    """What the cyclic collector would free, collected by hand at the end."""
    gc.collect()
    was_enabled = gc.isenabled()
    gc.disable()
    gc.set_debug(gc.DEBUG_SAVEALL)
    try:
        yield gc.garbage
    finally:
        gc.set_debug(0)
        gc.garbage.clear()
        if was_enabled:
            gc.enable()


def test_the_examples_have_render_prims() -> None:
    assert any("RenderSettings" in shot.read_text() for shot in SHOTS)


@pytest.mark.parametrize("shot", SHOTS, ids=lambda shot: shot.parent.name)
def test_a_lint_leaves_no_reference_cycles(shot: Path, garbage: list[object]) -> None:
    usdrender_lint.lint_file(shot)  # the imports' and first lint's one-time objects
    gc.collect()
    garbage.clear()

    findings = usdrender_lint.lint_file(shot)
    del findings
    gc.collect()

    kinds = sorted({type(thing).__qualname__ for thing in garbage})
    assert garbage == [], f"a lint of {shot.name} left cycles of {kinds}"


def _values_and_names(ctx: Context, prim) -> tuple[PrimValues, list[str]]:
    values = prim_values(prim)
    return values, list(values.authored_names())


class HoldsValuesRule(Rule):
    """Test-only rule: caches an answer that holds its prim's values.

    ## What it does
    Reports nothing; its ``ctx.cached`` answer holds the prim's PrimValues, a
    cycle through that object's memo while the lint runs.
    """

    code = "TX906"
    name = "test-holds-values"
    severity = Severity.INFO
    prim_types = (schemas.RenderSettings,)

    def check_prim(self, prim, ctx):
        ctx.cached(_values_and_names, prim)
        return ()


def test_no_cycle_of_a_plugin_rule_outlives_its_lint(garbage: list[object]) -> None:
    """Whatever a rule caches on a prim is dropped as the lint ends (forget_prim_answers)."""
    shot = EXAMPLES / "framing_shot" / "shot.usda"
    linter = Linter([HoldsValuesRule()])
    linter.lint_path(str(shot))
    gc.collect()
    garbage.clear()

    linter.lint_path(str(shot))
    gc.collect()

    kinds = sorted({type(thing).__qualname__ for thing in garbage})
    assert garbage == [], f"the lint left cycles of {kinds}"
