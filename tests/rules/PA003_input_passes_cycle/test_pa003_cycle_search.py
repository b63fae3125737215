"""PA003 beyond the fixtures: the cycle search itself and the message."""

from __future__ import annotations

from pathlib import Path

from usdrender_lint.rules._passes import find_cycles
from usdrender_lint.rules.passes.pa003_input_passes_cycle import InputPassesCycle
from usdrender_lint.testing import lint

HERE = Path(__file__).parent


def test_each_cycle_once_rotated_to_smallest_node() -> None:
    graph = {"c": ["a"], "a": ["b"], "b": ["c", "b"], "d": ["a"]}
    assert find_cycles(graph) == [("a", "b", "c"), ("b",)]


def test_acyclic_graphs_and_missing_nodes() -> None:
    assert find_cycles({"a": ["b", "c"], "b": ["d"], "c": ["d"], "d": []}) == []
    assert find_cycles({"a": ["unknown"]}) == []


def test_long_chain_does_not_recurse() -> None:
    chain = {i: [i + 1] for i in range(5000)}
    chain[4999] = [0]
    (cycle,) = find_cycles(chain)
    assert len(cycle) == 5000 and cycle[0] == 0


def test_message_lists_the_cycle_path() -> None:
    findings = lint(HERE / "fail_self_and_three.usda", [InputPassesCycle()])
    messages = sorted(f.message for f in findings)
    assert len(messages) == 2
    assert "</Render/b> -> </Render/c> -> </Render/d> -> </Render/b>" in messages[0]
    assert "lists itself in inputPasses: </Render/self> -> </Render/self>" in messages[1]
