"""The camera values the CA rules check: where Default is the only rendered time,
first_failure checks the values the lint already holds (PrimValues), which
must be those it read per check before (``Get()`` at Default, else the
schema fallback)."""

from __future__ import annotations

from typing import Any

import pytest
from pxr import Usd
from rule_support import stage_from_text

from usdrender_lint.api.cache import LintCache, lint_cache
from usdrender_lint.api.context import Context
from usdrender_lint.api.resolve import DEFAULT_TIME, PrimValues
from usdrender_lint.rules._camera import _reader, _value_at, first_failure

NAMES = ("focalLength", "horizontalAperture", "clippingRange", "projection")
WEAKER = '#usda 1.0\nover "cam"\n{\n    float focalLength = 50\n}\n'


def _camera(body: str) -> str:
    return f'#usda 1.0\ndef Camera "cam"\n{{\n{body}\n}}\n'


@pytest.mark.parametrize(
    "body",
    [
        "",
        "float focalLength = 35\n    float2 clippingRange = (1, 10)",
        "float focalLength = None",  # blocked: the fallback
        "double focalLength = 35",  # mistyped: unauthored (SE016's), the fallback
        'float focalLength = -1\n    token projection = "fisheye"',
        "float horizontalAperture.timeSamples = {}",  # the field, but no sample
    ],
)
@pytest.mark.parametrize("weaker", [False, True])
def test_values_at_default_are_those_each_check_read(body: str, weaker: bool) -> None:
    stage = stage_from_text(_camera(body), *([WEAKER] if weaker else []))
    prim = stage.GetPrimAtPath("/cam")
    seen: list[tuple[Any, ...]] = []

    def check(*values: Any) -> None:
        seen.append(values)

    varying = "timeSamples" in body
    with lint_cache(LintCache(without_clips=True, without_varying=not varying)) as cache:
        ctx = Context(stage=stage, file="memory.usda", cache=cache)
        assert first_failure(prim, NAMES, check, ctx) is None
    values = PrimValues(prim)
    expected = tuple(_value_at(_reader(values, name), DEFAULT_TIME) for name in NAMES)
    assert seen == [expected]


def test_a_sampled_value_is_still_read_at_its_times() -> None:
    stage = stage_from_text(_camera("float focalLength.timeSamples = {1: 35, 2: -1}"))
    prim = stage.GetPrimAtPath("/cam")
    with lint_cache(LintCache(without_clips=True)) as cache:
        ctx = Context(stage=stage, file="memory.usda", cache=cache)
        failure = first_failure(prim, ("focalLength",), lambda f: "bad" if f < 0 else None, ctx)
    assert failure == (Usd.TimeCode(2), "bad")


def test_no_value_is_read_again_at_default(monkeypatch: pytest.MonkeyPatch) -> None:
    stage = stage_from_text(_camera("float focalLength = 35\n    float2 clippingRange = (1, 10)"))
    prim = stage.GetPrimAtPath("/cam")
    reads: list[str] = []
    get = Usd.Attribute.Get

    def counting(attr: Usd.Attribute, *args: Any) -> Any:
        reads.append(attr.GetName())
        return get(attr, *args)

    monkeypatch.setattr(Usd.Attribute, "Get", counting)
    with lint_cache(LintCache(without_clips=True, without_varying=True)) as cache:
        ctx = Context(stage=stage, file="memory.usda", cache=cache)
        for _ in range(3):  # three CA checks of one camera
            assert first_failure(prim, NAMES, lambda *values: None, ctx) is None
    assert reads == []
