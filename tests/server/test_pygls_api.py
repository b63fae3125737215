"""The server stands on pygls's public API only: pygls's underscore names
(its protocol's ``_send_response`` and ``_workspace``, its workspace's
``_create_text_document``) change between its releases, and an upgrade that
renamed one would break the server where no test of ours looks."""

from __future__ import annotations

import ast
import importlib
import inspect

from conftest import REPO

SERVER = REPO / "usdrender_lint" / "server"
#: The pygls modules whose classes the server uses or extends.
PYGLS_MODULES = (
    "pygls.server",
    "pygls.lsp.server",
    "pygls.protocol.json_rpc",
    "pygls.protocol.language_server",
    "pygls.workspace.workspace",
    "pygls.workspace.text_document",
    "pygls.workspace.position_codec",
)


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def pygls_private_names() -> set[str]:
    """Every underscore attribute and method pygls's modules define or read."""
    names: set[str] = set()
    for module in PYGLS_MODULES:
        tree = ast.parse(inspect.getsource(importlib.import_module(module)))
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and _private(node.attr):
                names.add(node.attr)
            elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and _private(node.name):
                names.add(node.name)
    return names


def internals_used(source: str, private: set[str]) -> list[str]:
    """Where ``source`` reads, writes or overrides one of pygls's underscore
    names, imports one, or swaps an object's class."""
    found: list[tuple[int, str]] = []
    for node in ast.walk(ast.parse(source)):
        line = getattr(node, "lineno", 0)
        if isinstance(node, ast.Attribute) and (node.attr in private or node.attr == "__class__"):
            if node.attr == "__class__" and not isinstance(node.ctx, ast.Store):
                continue
            found.append((line, f".{node.attr}"))
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and node.name in private:
            found.append((line, f"def {node.name}"))
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("pygls"):
            names = [a.name for a in node.names if _private(a.name)]
            if names or any(_private(part) for part in (node.module or "").split(".")):
                found.append((line, f"from {node.module} import {names}"))
    return [f"line {line}: {what}" for line, what in sorted(found)]


def test_the_server_uses_no_pygls_internals() -> None:
    private = pygls_private_names()
    assert {"_send_response", "_workspace", "_create_text_document"} <= private
    used = {
        path.name: internals_used(path.read_text(encoding="utf-8"), private)
        for path in sorted(SERVER.glob("*.py"))
    }
    assert {name: found for name, found in used.items() if found} == {}


def test_the_check_sees_what_the_server_used_to_do() -> None:
    private = pygls_private_names()
    before = (
        "class P(LanguageServerProtocol):\n"
        "    def handle_message(self, message):\n"
        "        if self._workspace is None:\n"
        "            self._send_response(1, error=None)\n"
        "class W(Workspace):\n"
        "    def _create_text_document(self, uri):\n"
        "        return None\n"
        "def initialize(ls):\n"
        "    ls.workspace.__class__ = W\n"
    )
    assert internals_used(before, private) == [
        "line 3: ._workspace",
        "line 4: ._send_response",
        "line 6: def _create_text_document",
        "line 9: .__class__",
    ]
