"""engine/layer_words.py: what a layer file can hold, from its bytes. A word it
denies must be nowhere in the layer, as USD reads it; anything it cannot read
for sure may hold every word."""

from __future__ import annotations

import shutil
import struct
from pathlib import Path

import pytest
from pxr import Sdf, Tf, Vt

from usdrender_lint.engine import Linter, layer_words, suppress
from usdrender_lint.engine.layer_words import WORDS, may_hold, without_external_arcs
from usdrender_lint.layers.crate import lz4_block
from usdrender_lint.testing import all_rules


def _readable(path: Path) -> bool:
    try:
        return Sdf.Layer.FindOrOpen(str(path)) is not None
    except Tf.ErrorException:
        return False  # ST001's fixtures, and a few others that USD refuses on purpose


FIXTURES = [
    p for p in sorted((Path(__file__).parents[1] / "rules").glob("*/*.usda")) if _readable(p)
]


def _words_usd_sees(layer: Sdf.Layer) -> set[str]:
    """The WORDS the layer's specs hold as field names or dictionary keys."""
    found: set[str] = set()
    if layer.subLayerPaths:
        found.add("subLayers")

    def visit(path: Sdf.Path) -> None:
        spec = layer.GetObjectAtPath(path)
        if spec is None:
            return
        keys = set(spec.ListInfoKeys())
        if isinstance(spec, Sdf.PrimSpec):
            if spec.hasReferences:
                keys.add("references")
            if spec.hasPayloads:
                keys.add("payload")
            if len(spec.variantSets):
                keys.add("variantSetChildren")
        found.update(keys & set(WORDS))
        for key in ("customData", "clips"):
            if key in keys:
                found.update(_dictionary_keys(spec.GetInfo(key)) & set(WORDS))

    layer.Traverse(Sdf.Path.absoluteRootPath, visit)
    return found


def _dictionary_keys(value: object) -> set[str]:
    if not isinstance(value, dict):
        return set()
    keys = set(value)
    for inner in value.values():
        keys |= _dictionary_keys(inner)
    return keys


@pytest.mark.parametrize("fixture", FIXTURES, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_a_crate_holds_every_word_usd_reads_in_it(fixture: Path, tmp_path: Path) -> None:
    source = Sdf.Layer.FindOrOpen(str(fixture))
    crate = tmp_path / (fixture.stem + ".usdc")
    assert source.Export(str(crate))
    key = layer_words._key(str(crate))
    assert key is not None
    scan = layer_words._scan(key)
    assert scan.kind == "crate", "usd-core's crate must decode"
    assert _words_usd_sees(Sdf.Layer.FindOrOpen(str(crate))) <= scan.words
    assert scan.specs == Sdf.CrateInfo.Open(str(crate)).GetSummaryStats().numSpecs
    assert _words_usd_sees(source) <= may_hold(str(fixture), WORDS)


def test_a_crate_without_a_word_denies_it(tmp_path: Path) -> None:
    layer = Sdf.Layer.CreateNew(str(tmp_path / "plain.usdc"))
    spec = Sdf.CreatePrimInLayer(layer, "/World/Mesh")
    spec.specifier = Sdf.SpecifierDef
    spec.typeName = "Mesh"
    layer.Save()
    assert may_hold(str(tmp_path / "plain.usdc"), WORDS) == set()
    assert without_external_arcs(str(tmp_path / "plain.usdc"))
    spec.customData = {"usdrender_lint": {"ignore": Vt.StringArray(["SE003"])}}
    spec.referenceList.Prepend(Sdf.Reference("./other.usda"))
    layer.Save()
    assert may_hold(str(tmp_path / "plain.usdc"), WORDS) == {"usdrender_lint", "references"}
    assert not without_external_arcs(str(tmp_path / "plain.usdc"))


def test_text_is_read_as_bytes_and_escapes_may_hide_a_word(tmp_path: Path) -> None:
    plain = tmp_path / "plain.usda"
    plain.write_text('#usda 1.0\ndef Mesh "m"\n{\n}\n')
    assert may_hold(str(plain), WORDS) == set() and without_external_arcs(str(plain))
    escaped = tmp_path / "escaped.usda"
    escaped.write_text(
        '#usda 1.0\ndef "p" (\n    customData = {\n        dictionary "usdrender\\x5flint" = '
        '{\n            string[] ignore = ["SE003"]\n        }\n    }\n)\n{\n}\n'
    )
    assert dict(Sdf.Layer.FindOrOpen(str(escaped)).GetPrimAtPath("/p").customData) == {
        "usdrender_lint": {"ignore": Vt.StringArray(["SE003"])}
    }
    assert "usdrender_lint" in may_hold(str(escaped), WORDS)
    arc = tmp_path / "arc.usda"
    arc.write_text('#usda 1.0\ndef "p" (\n    references = @./x.usda@\n)\n{\n}\n')
    assert not without_external_arcs(str(arc))


def _damaged_crates(tmp_path: Path) -> list[Path]:
    layer = Sdf.Layer.CreateNew(str(tmp_path / "good.usdc"))
    Sdf.CreatePrimInLayer(layer, "/A").specifier = Sdf.SpecifierDef
    layer.Save()
    data = (tmp_path / "good.usdc").read_bytes()
    (toc,) = struct.unpack_from("<q", data, 16)
    damaged = {
        "truncated": data[: len(data) // 2],
        "future-version": data[:8] + bytes([1, 0, 0]) + data[11:],
        "bad-toc": data[:16] + struct.pack("<q", len(data) + 10) + data[24:],
        "zeroed-tokens": _zero_tokens(data, toc),
        "header-only": data[:16],
    }
    paths = []
    for name, content in damaged.items():
        path = tmp_path / f"{name}.usdc"
        path.write_bytes(content)
        paths.append(path)
    return paths


def _zero_tokens(data: bytes, toc: int) -> bytes:
    (count,) = struct.unpack_from("<Q", data, toc)
    for index in range(count):
        name, start, size = struct.unpack_from("<16sqq", data, toc + 8 + 32 * index)
        if name.rstrip(b"\0") == b"TOKENS":
            return data[: start + 24] + b"\x00" * (size - 24) + data[start + size :]
    raise AssertionError("no TOKENS section")


def test_what_cannot_be_read_for_sure_may_hold_every_word(tmp_path: Path) -> None:
    others = [tmp_path / "missing.usdc", tmp_path / "package.usdz", tmp_path / "text.usdc"]
    shutil.make_archive(str(tmp_path / "package"), "zip", tmp_path)
    (tmp_path / "package.zip").rename(tmp_path / "package.usdz")
    (tmp_path / "text.usdc").write_text("not a layer")
    for path in [*_damaged_crates(tmp_path), *others]:
        assert may_hold(str(path), WORDS) == set(WORDS), path.name
        assert not without_external_arcs(str(path)), path.name


def test_an_edited_file_is_read_again(tmp_path: Path) -> None:
    path = tmp_path / "shot.usda"
    path.write_text('#usda 1.0\ndef "p"\n{\n}\n')
    assert may_hold(str(path), WORDS) == set()
    path.write_text('#usda 1.0\ndef "p" (\n    clips = {}\n)\n{\n}\n')
    assert may_hold(str(path), WORDS) == {"clips"}


def test_lz4_matches_that_overlap_what_they_write_repeat_their_period() -> None:
    # Literal "ab", then a match of length 6 at offset 2: "ababab" follows.
    block = bytes([0x22]) + b"ab" + struct.pack("<H", 2) + bytes([0x10]) + b"!"
    assert lz4_block(block, 0, len(block), 64) == b"abababab!"
    assert lz4_block(block, 0, len(block), 4) is None  # past the declared size
    assert lz4_block(bytes([0x20]) + b"ab" + b"\x00\x00", 0, 5, 64) is None


SUPPRESSED = """#usda 1.0
def Scope "Render"
{
    def RenderSettings "Settings" (
        customData = {
            dictionary usdrender_lint = {
                string[] ignore = ["SE003", "CA004"]
            }
        }
    )
    {
        uniform float4 dataWindowNDC = (1, 1, 0, 0)
    }
}
"""


@pytest.mark.parametrize("fmt", ["usda", "usdc"])
def test_suppressions_in_a_layer_of_either_format_are_found(tmp_path: Path, fmt: str) -> None:
    text = tmp_path / "shot.usda"
    text.write_text(SUPPRESSED)
    path = text if fmt == "usda" else tmp_path / "shot.usdc"
    if fmt == "usdc":
        assert Sdf.Layer.FindOrOpen(str(text)).Export(str(path))
    findings = Linter(all_rules()).lint_path(str(path)).findings
    codes = {f.code for f in findings}
    assert "SE003" not in codes  # silenced
    assert [f.message for f in findings if f.code == "UL001"] == [
        "suppression of 'CA004' is unused: CA004 reports nothing on this prim"
    ]


def test_without_the_key_in_any_layer_no_prim_s_custom_data_is_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    text = tmp_path / "shot.usda"
    text.write_text(SUPPRESSED.replace("usdrender_lint", "someone_else"))
    crate = tmp_path / "shot.usdc"
    assert Sdf.Layer.FindOrOpen(str(text)).Export(str(crate))

    def read(prim: object) -> bool:
        raise AssertionError("customData read although no layer holds a suppression")

    monkeypatch.setattr(suppress, "has_suppressions", read)
    for path in (text, crate):
        assert "SE003" in {f.code for f in Linter(all_rules()).lint_path(str(path)).findings}


def test_a_session_layer_of_variant_selections_holds_no_word() -> None:
    """--variants' own selections keep every shortcut; anything more may hold any word."""
    session = Sdf.Layer.CreateAnonymous()
    assert not layer_words.layers_may_hold([session], "usdrender_lint")
    Sdf.CreatePrimInLayer(session, "/Render/Settings").variantSelections["look"] = "b"
    assert layer_words.holds_only_selections(session)
    assert not layer_words.layers_may_hold([session], "usdrender_lint")
    over = session.GetPrimAtPath("/Render")
    over.SetInfo("customData", {"usdrender_lint": {"ignore": Vt.StringArray(["SE003"])}})
    assert not layer_words.holds_only_selections(session)
    assert layer_words.layers_may_hold([session], "usdrender_lint")
    over.ClearInfo("customData")
    Sdf.AttributeSpec(over, "x", Sdf.ValueTypeNames.Int)
    assert layer_words.layers_may_hold([session], "clips")
    session.Clear()
    Sdf.CreatePrimInLayer(session, "/Render").specifier = Sdf.SpecifierDef
    assert layer_words.layers_may_hold([session], "untyped")


@pytest.mark.parametrize("held", [True, False])
def test_a_text_layer_is_searched_for_each_word_when_first_asked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, held: bool
) -> None:
    """A lint asks for two or three words: the others are never searched for,
    and the answers are those of searching for every word at once."""
    if not held:
        monkeypatch.setattr(layer_words, "MAX_HELD_TEXT", 0)  # every word at the first read
    first, second = tmp_path / "first.usda", tmp_path / "second.usda"
    first.write_text('#usda 1.0\ndef "p" (\n    clips = {}\n    payload = @x.usda@\n)\n{\n}\n')
    second.write_text('#usda 1.0\ndef "q" (\n    inherits = </C>\n)\n{\n}\n')
    assert may_hold(str(first), ("clips",)) == {"clips"}
    assert may_hold(str(second), ("usdrender_lint",)) == set()  # now second's bytes are held
    assert may_hold(str(first), ("payload", "references")) == {"payload"}  # read again
    assert may_hold(str(second), WORDS) == {"inheritPaths"}
    assert may_hold(str(first), WORDS) == {"clips", "payload"}
    assert not without_external_arcs(str(first)) and without_external_arcs(str(second))
    key = layer_words._key(str(second))
    assert key is not None and layer_words._scan(key).unsearched == frozenset()


def test_a_text_layer_s_bytes_are_read_once_for_every_question(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The engine reads a text layer's bytes before USD does (the nesting
    check): the words are then answered from those bytes, not a second read."""
    path = tmp_path / "shot.usda"
    text = b'#usda 1.0\ndef "p" (\n    clips = {}\n    payload = @x.usda@\n)\n{\n}\n'
    path.write_bytes(text)
    assert layer_words.text_bytes(str(path)) == text

    def no_second_read(*args: object, **kwargs: object) -> None:
        raise AssertionError("the file was read again")

    monkeypatch.setattr(layer_words, "open", no_second_read, raising=False)
    assert layer_words.text_bytes(str(path)) == text
    assert may_hold(str(path), WORDS) == {"clips", "payload"}
    assert not without_external_arcs(str(path))


def test_only_a_text_layer_s_bytes_are_read_whole(tmp_path: Path) -> None:
    layer = Sdf.Layer.CreateNew(str(tmp_path / "plain.usdc"))
    Sdf.CreatePrimInLayer(layer, "/World").specifier = Sdf.SpecifierDef
    layer.Save()
    assert layer_words.text_bytes(str(tmp_path / "plain.usdc")) is None
    (tmp_path / "other.usda").write_bytes(b"#sdf 1.4.32\n")
    assert layer_words.text_bytes(str(tmp_path / "other.usda")) is None
    assert layer_words.text_bytes(str(tmp_path / "missing.usda")) is None


@pytest.mark.parametrize("size", [0, 1, 8191, 8192, 300_000])
def test_a_text_layer_s_bytes_are_its_whole_file(tmp_path: Path, size: int) -> None:
    """Read from its start again after its cookie is checked: every byte, once,
    whatever the file's size next to a read buffer's."""
    path = tmp_path / "shot.usda"
    text = b"#usda 1.0\n" + b"#" * size
    path.write_bytes(text)
    assert layer_words.text_bytes(str(path)) == text
    path.write_bytes(b"#usda ")  # the cookie alone
    assert layer_words.text_bytes(str(path)) == b"#usda "
    path.write_bytes(b"#usd")  # shorter than the cookie
    assert layer_words.text_bytes(str(path)) is None


def test_the_words_of_several_layers_are_those_each_layer_may_hold(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A lint asks each used layer's file once for all its words: the answer is
    the words some layer may hold, as asking word by word says."""
    first, second = tmp_path / "first.usda", tmp_path / "second.usda"
    first.write_text('#usda 1.0\ndef "p" (\n    clips = {}\n)\n{\n}\n')
    second.write_text('#usda 1.0\ndef "q"\n{\n    double x.spline = {}\n}\n')
    layers = [Sdf.Layer.FindOrOpen(str(path)) for path in (first, second)]
    words = ("clips", "timeSamples", "spline", "usdrender_lint")
    held = layer_words.words_layers_may_hold(layers, words)
    assert held == {"clips", "spline"}
    assert held == {w for w in words if layer_words.layers_may_hold(layers, w)}
    session = Sdf.Layer.CreateAnonymous()
    assert layer_words.words_layers_may_hold([session, *layers], words) == held
    Sdf.CreatePrimInLayer(session, "/Render").specifier = Sdf.SpecifierDef
    assert layer_words.words_layers_may_hold([*layers, session], words) == set(words)
    stats: list[str] = []
    key = layer_words._key
    monkeypatch.setattr(layer_words, "_key", lambda path: stats.append(path) or key(path))
    layer_words.words_layers_may_hold(layers, words)
    assert stats == [str(first), str(second)]  # one look at each file
