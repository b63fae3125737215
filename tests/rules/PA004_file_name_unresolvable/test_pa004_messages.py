"""PA004 messages name the cause: unset variables, expression errors, the layer."""

from __future__ import annotations

from pathlib import Path

from usdrender_lint.rules.passes.pa004_file_name_unresolvable import FileNameUnresolvable
from usdrender_lint.testing import lint

HERE = Path(__file__).parent


def _messages(name: str) -> dict[str, str]:
    findings = lint(HERE / name, [FileNameUnresolvable()])
    return {f.location.path: f.message for f in findings}


def test_expression_messages() -> None:
    messages = _messages("fail_expressions.usda")
    assert "expression variable(s) SEQ not set" in messages["/Render/unset.fileName"]
    assert "Missing ending '}'" in messages["/Render/malformed.fileName"]
    assert "'./shots/sq010/missing.nk'" in messages["/Render/wrongShot.fileName"]


def test_names_the_authoring_layer() -> None:
    (message,) = _messages("fail_from_reference.usda").values()
    assert "does not resolve relative to passes.usda" in message
