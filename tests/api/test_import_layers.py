"""The package's layers, as the tree shows them: every import (lazy ones
included) goes from a higher layer to a lower one or stays inside its own
component, and no modules import each other in a cycle.

Run this file as a script to print the component graph.
"""

from __future__ import annotations

import ast
import sys
from collections import defaultdict
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
PACKAGE = "usdrender_lint"

#: Component -> the components it may import (itself always). Lowest first.
ALLOWED: dict[str, set[str]] = {
    # records: @dataclass without its import-time cost, for every layer.
    "records": set(),
    "model": {"records"},
    "paths": set(),
    "atomic": set(),
    # reading: a file the user names as an input (a baseline, a report), never waited on forever.
    "reading": {"atomic"},
    # debug: USDRENDER_LINT_DEBUG's tracebacks, from any process.
    "debug": {"atomic"},
    "entrypoints": set(),
    # settings_table: every setting declared once, below the config and the CLI.
    "settings_table": {"records", "model"},
    "config": {"records", "model", "settings_table"},
    # layers: the floor below the engine and the fixer (.usda text, layer files, writing).
    "layers": {"records", "api", "paths", "atomic"},
    # report_json: the report's JSON codec, beside the model.
    "report_json": {"model", "paths", "reading"},
    "api": {"records", "model"},
    "registry": {"records", "api", "entrypoints", "model"},
    "rules": {"api", "model"},
    # paths: names that are not UTF-8 go to USD as bytes and come back escaped.
    "engine": {"records", "api", "debug", "layers", "model", "paths", "registry"},
    # formatters.html reads the linted files' render specification through
    # running.report_views (which computes it with render_spec): above the
    # other formatters, a layering the HTML report's owner may want to revisit.
    # formatters.full reads a layer's lines and a statement's columns from layers.
    "formatters": {
        "records", "model", "paths", "entrypoints", "layers", "report_json", "running",
    },
    "fixing": {"records", "api", "debug", "engine", "layers", "model", "paths"},
    "profiles": {"records", "api", "model", "registry"},
    "render_spec": {"records", "api", "engine", "model", "paths", "profiles"},
    # explain: a rule's documentation with its profiles (explain, SARIF, the site).
    "explain": {"api", "model", "profiles"},
    # running reads the JSON format's records back (merge, the result cache).
    "running": {
        "api", "atomic", "config", "debug", "engine", "entrypoints", "explain", "fixing",
        "formatters", "layers", "model", "paths", "profiles", "reading", "records", "registry",
        "render_spec", "report_json", "settings_table",
    },
    "testing": {"records", "api", "engine", "model", "registry"},
    # The validation plugins lint and fix one stage as check does (running.stage_lints,
    # fixing.single).
    "usdplugin": {
        "records", "api", "atomic", "engine", "fixing", "model", "registry", "rules", "running",
    },
    "assetvalidator": {
        "records", "api", "engine", "fixing", "model", "registry", "rules", "running",
    },
    # server: the language server (usdrender-lint server) lints documents as check does.
    # paths: a URI's name that is not UTF-8 is the file's bytes.
    "server": {
        "records", "api", "engine", "explain", "fixing", "layers", "model", "paths", "registry",
        "running", "__init__",
    },
    "cli": {
        "api", "atomic", "config", "engine", "entrypoints", "explain", "fixing", "formatters",
        "model", "paths", "profiles", "records", "registry", "running", "render_spec", "server",
        "settings_table", "usdplugin", "__init__",
    },
    # running.interrupts: the signal handlers, installed before the CLI's imports.
    "__main__": {"cli", "running"},
    "__init__": {"running"},
}  # fmt: skip


def _modules() -> dict[str, Path]:
    """Module name -> file, for the package and the rules (installed as usdrender_lint.rules)."""
    found = {}
    for root, prefix in ((REPO / PACKAGE, PACKAGE), (REPO / "rules", f"{PACKAGE}.rules")):
        for path in root.rglob("*.py"):
            parts = list(path.relative_to(root).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            found[".".join([prefix, *parts])] = path
    return found


def _imports(name: str, path: Path, modules: set[str]) -> set[str]:
    """The package modules ``name`` imports (``from . import x`` imports x, not ``.``)."""
    is_package = path.name == "__init__.py"
    package = name if is_package else name.rpartition(".")[0]
    targets = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            targets.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                base = ".".join([*anchor, base] if base else anchor)
            submodules = {f"{base}.{alias.name}" for alias in node.names} & modules
            targets.update(submodules or {base})
    return targets & modules


def _component(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def _graph() -> dict[str, set[str]]:
    modules = _modules()
    graph = {}
    for name, path in modules.items():
        graph[name] = _imports(name, path, set(modules)) - {name}
    return graph


def test_every_import_goes_down_the_layers() -> None:
    wrong = []
    for module, targets in _graph().items():
        source = _component(module)
        for target in targets:
            destination = _component(target)
            if destination != source and destination not in ALLOWED.get(source, set()):
                wrong.append(f"{module} -> {target}")
    assert not wrong, "imports against the layers:\n" + "\n".join(sorted(wrong))


def test_every_module_belongs_to_a_known_component() -> None:
    assert {_component(m) for m in _graph()} <= set(ALLOWED)


def test_no_import_cycles() -> None:
    graph = _graph()
    cycles = []
    state: dict[str, int] = {}  # 1 on the stack, 2 done

    def visit(module: str, stack: list[str]) -> None:
        state[module] = 1
        stack.append(module)
        for target in sorted(graph[module]):
            # A package's __init__ importing its own submodules is not a cycle of design.
            if target.startswith(module + "."):
                continue
            if state.get(target) == 1:
                cycles.append(" -> ".join([*stack[stack.index(target) :], target]))
            elif target not in state:
                visit(target, stack)
        stack.pop()
        state[module] = 2

    for module in sorted(graph):
        if module not in state:
            visit(module, [])
    assert not cycles, "import cycles:\n" + "\n".join(cycles)


def test_rules_import_only_the_rule_api() -> None:
    for module, targets in _graph().items():
        if _component(module) == "rules":
            assert {_component(t) for t in targets} <= {"rules", "api", "model"}, module


def component_graph() -> dict[str, set[str]]:
    edges: dict[str, set[str]] = defaultdict(set)
    for module, targets in _graph().items():
        for target in targets:
            if _component(target) != _component(module):
                edges[_component(module)].add(_component(target))
    return edges


if __name__ == "__main__":
    for source, targets in sorted(component_graph().items()):
        print(f"{source:12} -> {', '.join(sorted(targets))}")
    sys.exit(0)
