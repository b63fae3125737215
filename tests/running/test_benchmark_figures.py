"""benchmarks/run.py's figures: the ratios it prints against a baseline."""

from __future__ import annotations

from bench_support import load_script

run = load_script("run")


def _series(label: str, seconds: list[float]):
    series = run.Series(label, ["true"])
    series.samples = [run.Sample(s, 1024, s) for s in seconds]
    return series


def test_a_paired_ratio_is_the_median_of_each_rounds_ratio() -> None:
    # The machine slows down over the run: each round's ratio stays 1.2.
    bare = _series("bare", [1.0, 2.0, 4.0])
    check = _series("check", [1.2, 2.4, 4.8])
    assert round(run.paired(check, bare), 6) == 1.2
    assert round(check.median() / bare.median(), 6) == 1.2
    # A slow round of one side alone moves the paired figure by one round only.
    check = _series("check", [1.2, 2.4, 40.0])
    assert round(run.paired(check, bare), 6) == 1.2
    assert "paired 1.20x" in run.row(check, bare)
