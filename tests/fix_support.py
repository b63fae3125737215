"""Helpers the fixing tests share: the command with JSON output, writing a layer,
the codes of a report, and a layer's specs as comparable text."""

from __future__ import annotations

import json
from pathlib import Path

from click.testing import CliRunner
from pxr import Sdf

from usdrender_lint.cli import cli


def check(*args: str):
    base = ["check", "--isolated", "--jobs", "1", "--timeout", "0", "--format", "json"]
    result = CliRunner().invoke(cli, [*base, *args])
    document = json.loads(result.stdout) if result.stdout.startswith("{") else None
    return result, document


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def codes(document: dict) -> list[str]:
    return [f["code"] for result in document["files"] for f in result["findings"]]


def _text(value) -> str:
    """A field value as text; list ops (whose repr is an address) by their items."""
    if isinstance(value, Sdf.PathListOp | Sdf.TokenListOp | Sdf.StringListOp):
        parts = ("explicitItems", "prependedItems", "appendedItems", "deletedItems")
        return repr([value.isExplicit, *(list(getattr(value, part)) for part in parts)])
    return repr(value)


def spec_fields(layer: Sdf.Layer) -> dict[str, dict[str, str]]:
    """Every spec of a layer with its fields, as comparable text."""
    fields: dict[str, dict[str, str]] = {}

    def visit(path: Sdf.Path) -> None:
        spec = layer.GetObjectAtPath(path)
        if spec is not None:
            fields[str(path)] = {key: _text(spec.GetInfo(key)) for key in spec.ListInfoKeys()}

    layer.Traverse(Sdf.Path.absoluteRootPath, visit)
    return fields


#: One orderedVars target that names nothing (PR005, an unsafe fix removes it).
ONE_MISSING = """#usda 1.0

def Scope "Render"
{
    def RenderProduct "Beauty"
    {
        token productName = "beauty.exr"
        rel orderedVars = [</Render/Color>, </Render/Missing1>]
    }

    def RenderVar "Color"
    {
        string sourceName = "Ci"
    }
}
"""
#: A second one on the same relationship: a finding of the same fingerprint.
TWO_MISSING = ONE_MISSING.replace("</Render/Missing1>]", "</Render/Missing1>, </Render/Missing2>]")
