"""layers.usda_text.statements: the statements of one block with the spans of
their parts, keyed so that a file and Sdf's export of it pair up."""

from __future__ import annotations

from pathlib import Path

import pytest
from pxr import Sdf

from usdrender_lint.layers.usda_text import (
    BODY,
    DICT,
    META,
    VARIANTS,
    element_spans,
    layer_text,
    statements,
)

TEXT = """#usda 1.0 # header { not a block
(
    "layer doc"
    defaultPrim = "Render"; upAxis = "Y"
    subLayers = [@a.usda@ (offset = 1), @b.usda@]
)

def Scope "Render" (  # a comment with } and (
    prepend apiSchemas = ["CollectionAPI:c"]
    customData = {
        string "odd key" = "}"
        dictionary usdrender_lint = {
            string[] ignore = ["SE003"]
        }
    }
)
{
    reorder nameChildren = ["B", "A"]
    custom uniform float3[] xformOp:translate.timeSamples = {
        1: [(0, 1, 2)],
    }
    rel material:binding = </M> (
        bindMaterialAs = "strongerThanDescendants"
    )
    float2 clip = (1e-05, 10) (doc = "near, far")
    asset file = @a{b}.exr@
    string s = "a # not a comment"
    rel empty

    variantSet "look" = {
        "red" (doc = "r") {
            over "A" {
            }
        }
        'blue'
        {
        }
    }

    def "B"
    {
    }

    class RenderSettings "A"
    {
    }
}
"""


def read(text: str, span: tuple[int, int]) -> str:
    return text[span[0] : span[1]]


def test_the_example_is_a_layer_usd_reads() -> None:
    assert Sdf.Layer.CreateAnonymous(".usda").ImportFromString(TEXT)


def test_the_layer_has_its_header_metadata_and_body() -> None:
    top = layer_text(TEXT)
    assert TEXT[: top.header_end] == "#usda 1.0 # header { not a block\n"
    assert read(TEXT, top.meta).startswith('(\n    "layer doc"')
    meta = statements(TEXT, top.meta[0] + 1, top.meta[1] - 1, META)
    assert [s.key for s in meta] == [
        ("entry", "", "doc"),
        ("entry", "", "defaultPrim"),
        ("entry", "", "upAxis"),
        ("entry", "", "subLayers"),
    ]
    assert read(TEXT, meta[3].value) == "[@a.usda@ (offset = 1), @b.usda@]"
    (render,) = statements(TEXT, *top.body, BODY)
    assert render.key == ("prim", "Render")


def test_a_prim_has_words_metadata_and_body() -> None:
    (render,) = statements(TEXT, *layer_text(TEXT).body, BODY)
    assert [read(TEXT, w) for w in render.words] == ["def", "Scope", '"Render"']
    meta = statements(TEXT, render.meta[0] + 1, render.meta[1] - 1, META)
    assert [s.key for s in meta] == [
        ("entry", "prepend", "apiSchemas"),
        ("entry", "", "customData"),
    ]
    custom = meta[1]
    entries = statements(TEXT, custom.value[0] + 1, custom.value[1] - 1, DICT)
    assert [s.key for s in entries] == [("entry", "", "odd key"), ("entry", "", "usdrender_lint")]
    body = statements(TEXT, render.body[0] + 1, render.body[1] - 1, BODY)
    assert [s.key for s in body] == [
        ("reorder", "nameChildren"),
        ("property", "xformOp:translate", "", "timeSamples"),
        ("property", "material:binding", "", ""),
        ("property", "clip", "", ""),
        ("property", "file", "", ""),
        ("property", "s", "", ""),
        ("property", "empty", "", ""),
        ("variantSet", "look"),
        ("prim", "B"),
        ("prim", "A"),
    ]
    by_name = {s.key[1]: s for s in body}
    assert read(TEXT, by_name["clip"].value) == "(1e-05, 10)"
    assert read(TEXT, by_name["clip"].meta) == '(doc = "near, far")'
    assert read(TEXT, by_name["file"].value) == "@a{b}.exr@"
    assert read(TEXT, by_name["s"].value) == '"a # not a comment"'
    assert by_name["empty"].value is None
    binding = by_name["material:binding"]
    assert read(TEXT, binding.meta).startswith("(\n        bindMaterialAs")
    looks = by_name["look"]
    variants = statements(TEXT, looks.value[0] + 1, looks.value[1] - 1, VARIANTS)
    assert [v.key for v in variants] == [("variant", "red"), ("variant", "blue")]
    assert read(TEXT, variants[0].meta) == '(doc = "r")'


def test_array_and_tuple_elements() -> None:
    text = '[ "a",  # one\n  "b" , (0, 1), ]'
    assert [read(text, span) for span in element_spans(text, (0, len(text)))] == [
        '"a"',
        '"b"',
        "(0, 1)",
    ]


@pytest.mark.parametrize("name", ["test_0055", "test_0149"])
def test_a_file_and_its_sdf_export_pair_up(shared_dir: Path, name: str) -> None:
    path = shared_dir / "corpus/files/Autodesk__arnold-usd/testsuite" / name / "data/test.usda"
    if not path.is_file():
        pytest.skip("not in the corpus")
    text = path.read_text(encoding="utf-8")
    exported = Sdf.Layer.FindOrOpen(str(path)).ExportToString()
    keys = []
    for source in (text, exported):
        top = layer_text(source)
        keys.append(sorted(s.key for s in statements(source, *top.body, BODY)))
    assert keys[0] == keys[1]
