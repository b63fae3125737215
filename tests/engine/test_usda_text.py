"""Line lookup in text layers: the lazy lookup against a plain token-by-token reference."""

from __future__ import annotations

import random
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from pxr import Sdf
from pytest import MonkeyPatch

from usdrender_lint.api.cache import lint_cache
from usdrender_lint.layers import usda_text
from usdrender_lint.layers.usda_text import comment_lines, index_usda, line_of

pytestmark = pytest.mark.heavy(seconds=19)

TESTS = Path(__file__).parents[1]
REPO = TESTS.parent

# --- reference: the straightforward scanner the lazy lookup replaced ----------------
# One regex token at a time, one state machine for the whole file. Kept here only to
# pin the lookup to it: same line for every spec path, None where it finds none.

# ";" ends a statement as a line end does (statements on one line).
_REF_INERT = r"""[^\n;"'@<#/{}()\[\]A-Za-z_]"""
_REF_TOKEN = re.compile(
    r"""
    (?P<newline>\n|;)
  | (?P<inert>INERT+|(?:\(INERT*\)INERT*)+)
  | (?P<space>[ \t\r\f\v]+)
  | (?P<comment>\#[^\n]*|//[^\n]*|/\*.*?\*/)
  | (?P<string>\"\"\".*?\"\"\"|'''.*?'''|"(?:\\.|[^"\\\n])*"|'(?:\\.|[^'\\\n])*')
  | (?P<asset>@@@.*?@@@|@[^@\n]*@)
  | (?P<path><[^>\n]*>)
  | (?P<word>[A-Za-z_][\w:.-]*(?:\[\])?)
  | (?P<punct>.)
    """.replace("INERT", _REF_INERT),
    re.VERBOSE | re.DOTALL,
)
_REF_QUALIFIERS = {"custom", "uniform", "varying", "config"}
_REF_QUALIFIERS |= {"prepend", "append", "add", "delete", "reorder"}
_REF_SPECIFIERS = {"def", "over", "class"}


def _ref_tokens(text: str) -> Iterator[tuple[str, str, int]]:
    line = 1
    for match in _REF_TOKEN.finditer(text):
        kind = match.lastgroup or "punct"
        if kind not in ("space", "comment", "inert"):
            yield kind, match.group(), line
        line += match.group().count("\n")


def _ref_unquote(token: str) -> str:
    for quote in ('"""', "'''", '"', "'"):
        if token.startswith(quote) and token.endswith(quote) and len(token) >= 2 * len(quote):
            return token[len(quote) : -len(quote)]
    return token


def reference_index(text: str) -> dict[str, int]:
    lines: dict[str, int] = {}
    stack = [("prim", "")]
    parens = 0
    statement: list[tuple[str, str, int]] = []
    pending = None

    def flush() -> None:
        words = [v for k, v, _ in statement if k == "word"]
        if not statement or stack[-1][0] not in ("prim", "variant") or not stack[-1][1]:
            return
        if statement[0][0] != "word" or words[0] in _REF_SPECIFIERS | {"variantSet"}:
            return
        rest = [w for w in words if w not in _REF_QUALIFIERS]
        if len(rest) >= 2:
            lines.setdefault(stack[-1][1] + "." + rest[1].split(".")[0], statement[0][2])

    tokens = list(_ref_tokens(text))
    i = 0
    while i < len(tokens):
        kind, value, line = tokens[i]
        i += 1
        if parens:
            parens += 1 if value in "([" else -1 if value in ")]" else 0
            continue
        if kind == "newline":
            flush()
            statement = []
            continue
        if statement and kind != "punct":
            statement.append((kind, value, line))
            continue
        top_kind, top_path = stack[-1]
        at_spec_level = not statement and top_kind in ("prim", "variant")
        if at_spec_level and kind == "word" and value in _REF_SPECIFIERS:
            j = i
            while j < len(tokens) and tokens[j][0] == "word":
                j += 1
            if j < len(tokens) and tokens[j][0] == "string":
                name = _ref_unquote(tokens[j][1])
                path = top_path + name if top_path.endswith("}") else top_path + "/" + name
                lines.setdefault(path, line)
                pending = ("prim", path)
                statement = [(kind, value, line)]
                i = j + 1
                continue
        if at_spec_level and value == "variantSet" and i < len(tokens) and tokens[i][0] == "string":
            pending = ("variantset", top_path + "{" + _ref_unquote(tokens[i][1]) + "=")
        if top_kind == "variantset" and kind == "string" and not statement:
            pending = ("variant", top_path + _ref_unquote(value) + "}")
        if value == "{":
            flush()
            stack.append(pending or ("other", top_path))
            pending = None
            statement = []
        elif value == "}":
            if len(stack) > 1:
                stack.pop()
            statement = []
        else:
            if value in "([":
                parens += 1
            statement.append((kind, value, line))
    flush()
    return lines


def reference_comment_lines(text: str) -> list[int]:
    found, line = [], 1
    for match in _REF_TOKEN.finditer(text):
        if match.lastgroup == "comment" and match.start():
            found.append(line)
        line += match.group().count("\n")
    return found


# --- equivalence on real layers ------------------------------------------------------


def _sdf_paths(path: Path) -> list[str]:
    """Every spec path Sdf lists in the layer (prims, variant sets, variants,
    properties, targets), or none when Sdf cannot read it."""
    try:
        layer = Sdf.Layer.FindOrOpen(str(path))
    except Exception:  # noqa: BLE001 - broken layers are in the fixtures on purpose
        return []
    paths: list[str] = []
    if layer is not None:
        layer.Traverse("/", lambda spec_path: paths.append(str(spec_path)))
    return paths


def _assert_same_lines(path: Path) -> int:
    text = path.read_text(encoding="utf-8", errors="replace")
    expected = reference_index(text)
    assert index_usda(text) == expected, path
    assert comment_lines(text) == reference_comment_lines(text), path
    asked = _sdf_paths(path) + list(expected) + ["/Nowhere", "/Nowhere.attr"]
    # One lazy layer asked in Sdf's order, one in reverse: what earlier lookups
    # read must not change later answers.
    for order in (asked, asked[::-1]):
        with lint_cache():  # a lint's lookups share one lazily read layer
            for spec_path in order:
                assert line_of(str(path), spec_path) == expected.get(spec_path), (path, spec_path)
    return len(asked)


def _usda_files(*roots: Path) -> list[Path]:
    return sorted(p for root in roots for p in root.rglob("*.usda"))


def test_same_lines_as_reference_on_fixtures_and_examples() -> None:
    files = _usda_files(TESTS, REPO / "examples")
    assert len(files) > 300
    assert sum(_assert_same_lines(path) for path in files) > 5000


def test_same_lines_as_reference_on_the_corpus(shared_dir: Path) -> None:
    files = _usda_files(shared_dir / "corpus" / "files")
    assert files
    for path in files:
        _assert_same_lines(path)


# --- hostile text ----------------------------------------------------------------------

HOSTILE = '''#usda 1.0
(
    doc = """a { brace, a } brace,
def Xform "InDoc" {
"""
    customLayerData = { string note = "def Scope \\"Fake\\" { // not a comment # nor this" }
)
/* def Xform "InBlockComment"
{
} */
def Xform "World" (
    variants = { string look = "a" }
    prepend variantSets = ["look", "lod"]
)
{   float onBraceLine = 1
    rel target = </World{look=a}cam.focalLength>
    string braces = "}}}{"  # def Xform "InComment" {
    string slashes = "// # /* not comments */"
    custom string notes = """two
lines { with } braces"""
    variantSet "look" = {
        "a" (doc = "variant a") {
            def Camera "cam"
            {
                float focalLength.timeSamples = {
                    1: 35,
                }
            }
            variantSet "lod" = {
                "high" {
                    def Mesh "def"
                    {
                        int[] faceVertexCounts = [4]
                    }
                }
            }
        }
        "b" {
            over "class" { }
        }
    }
    def Scope "over"
    {
        token variantSet = "not a variant set"
    }
}
'''


def _hostile_lines(text: str) -> dict[str, int]:
    index = index_usda(text)
    assert index == reference_index(text)
    return index


#: Lines counted by hand in HOSTILE.
HOSTILE_LINES = {
    "/World": 11,
    "/World.onBraceLine": 15,
    "/World.target": 16,
    "/World.braces": 17,
    "/World.slashes": 18,
    "/World.notes": 19,
    "/World{look=a}cam": 23,
    "/World{look=a}cam.focalLength": 25,
    "/World{look=a}{lod=high}def": 31,
    "/World{look=a}{lod=high}def.faceVertexCounts": 33,
    "/World{look=b}class": 39,
    "/World/over": 42,
    "/World/over.variantSet": 44,
}


def test_statements_separated_by_a_semicolon_have_their_lines() -> None:
    """USD reads ";" between two statements on one line as a line end: the second
    property had no line, so its finding named none."""
    text = (
        '#usda 1.0\ndef Scope "R"\n{\n    def RenderSettings "S"\n    {\n'
        "        uniform int2 resolution = (1, 1); uniform float4 dataWindowNDC = (0, 0, 1, 1)\n"
        "        rel camera = </R/S>;rel products = </R/P>\n    }\n}\n"
    )
    expected = {"/R/S.resolution": 6, "/R/S.dataWindowNDC": 6}
    expected |= {"/R/S.camera": 7, "/R/S.products": 7}
    lines = index_usda(text)
    assert {path: lines.get(path) for path in expected} == expected
    assert reference_index(text) == lines
    layer = Sdf.Layer.CreateAnonymous(".usda")
    assert layer.ImportFromString(text)  # USD reads it so
    assert layer.GetAttributeAtPath("/R/S.dataWindowNDC") is not None


def test_hostile_text_lines() -> None:
    index = _hostile_lines(HOSTILE)
    assert index == HOSTILE_LINES  # nothing from strings or comments ("InDoc", "Fake"...)


def test_hostile_text_lazy_lookups_match(tmp_path: Path) -> None:
    layer = tmp_path / "hostile.usda"
    layer.write_text(HOSTILE)  # Sdf refuses the target with a variant selection
    assert _assert_same_lines(layer) >= 15
    valid = tmp_path / "valid.usda"
    valid.write_text(HOSTILE.replace("</World{look=a}cam.focalLength>", "</World/over>"))
    assert Sdf.Layer.FindOrOpen(str(valid)) is not None
    assert _assert_same_lines(valid) > 30  # with every path Sdf lists


def test_crlf_line_endings_count_the_same_lines(tmp_path: Path) -> None:
    layer = tmp_path / "crlf.usda"
    layer.write_bytes(HOSTILE.replace("\n", "\r\n").encode())
    expected = _hostile_lines(HOSTILE)
    assert _hostile_lines(layer.read_bytes().decode()) == expected
    with lint_cache():
        for spec_path, line in expected.items():
            assert line_of(str(layer), spec_path) == line


def test_nesting_deeper_than_the_patterns_match_at_once() -> None:
    # Prim bodies, dictionaries and brackets nested past what one compiled pattern
    # matches are walked in Python; the lines must not move.
    depth = 3 * usda_text._DEPTH
    parts = ["#usda 1.0\n"]
    for level in range(depth):
        parts.append(f'def Xform "p{level}"\n{{\n    float a{level} = {level}\n')
    parts.append("    dictionary d = " + "{ dictionary d = " * depth + "{}" + " }" * depth + "\n")
    parts.append("    float[] v = " + "[(" * depth + "1" + ")]" * depth + "\n    float after = 1\n")
    parts.append("}\n" * depth)
    parts.append('def Xform "Sibling"\n{\n    float b = 1\n}\n')
    text = "".join(parts)
    index = _hostile_lines(text)
    deepest = "/" + "/".join(f"p{level}" for level in range(depth))
    assert index[deepest + ".after"] == 3 * depth + 4
    assert index["/Sibling.b"] == text.count("\n") - 1
    for spec_path, line in index.items():
        assert usda_text._Layer(text).lookup(spec_path) == line


def test_malformed_text_still_matches_the_reference() -> None:
    # Not USD, but the scanner must not crash or disagree on text Sdf refuses.
    for text in (
        'def Xform "A"\n{\n    float x = (1\n}\ndef Xform "B"\n{\n}\n',
        'def Xform "A"\n{\n    string s = "unterminated\n    float y = 1\n}\n',
        'def Xform "A" { float inline = 1 }\ndef "B"\n{\n    @a@ float z = 1\n}\n}\n}',
        'def Xform "A"\n{\n    float x = ]\n    /* open comment\n',
        'def Xform "A"\n{\n    ) float x = 1\n    float ] y = 1 ) ]\n    float z = 1\n}\n',
        'def Xform "A"\n{\n    def Xform "B" { ) ] }\n    float z = 1\n}\n',
        'def Xform "A"\n{\n    rel r = </A{v=x}B>\n    rel s = </A{v=x}B.attr[</C>]>\n}\n',
    ):
        index = _hostile_lines(text)
        for spec_path, line in index.items():
            assert usda_text._Layer(text).lookup(spec_path) == line


def test_damaged_hostile_text_matches_the_reference() -> None:
    # Deterministic damage (characters dropped, doubled, swapped in from the
    # structural set) to reach the scanner's odd corners.
    rng = random.Random(6)
    valid = 0
    structural = "{}()[]\"'@<>#/*\n =abcdef"
    for _ in range(400):
        chars = list(HOSTILE.replace("</World{look=a}cam.focalLength>", "</World/over>"))
        for _ in range(rng.randint(1, 6)):
            i = rng.randrange(len(chars))
            action = rng.randrange(3)
            if action == 0:
                del chars[i]
            elif action == 1:
                chars.insert(i, chars[i])
            else:
                chars[i] = rng.choice(structural)
        text = "".join(chars)
        index = _hostile_lines(text)  # a full read: always the reference's lines
        asked = list(index)[::-1] + ["/World.nothing", "/World{look=a}cam.x"]
        if _sdf_accepts(text):
            # Lazy reads too, on what Sdf reads (on broken text a block may end
            # inside a statement, which only a full read follows), tokenizing the
            # blocks they skip or skipping them over the skeleton (braces and atoms).
            expected = {spec_path: index.get(spec_path) for spec_path in asked}
            for read_by_sdf in (False, True):
                layer = usda_text._Layer(text, read_by_sdf=read_by_sdf)
                found = {spec_path: layer.lookup(spec_path) for spec_path in asked}
                assert found == expected, (read_by_sdf, text)
            valid += 1
    assert valid > 20, valid


def test_a_layer_sdf_read_skips_blocks_over_its_skeleton(monkeypatch: MonkeyPatch) -> None:
    # Brackets holding braces (metadata dictionaries), braces in strings, comments,
    # asset paths and <paths> in the skipped blocks: the skeleton keeps what their
    # patterns read, so the lines are the reference's without tokenizing the blocks.
    text = HOSTILE.replace("</World{look=a}cam.focalLength>", "</World/over>")
    expected = _hostile_lines(text)

    def tokenized(text: str, pos: int) -> int:
        raise AssertionError("a block of a layer Sdf read was tokenized")

    with monkeypatch.context() as patched:
        patched.setattr(usda_text, "_skip_block", tokenized)
        for spec_path, line in expected.items():
            layer = usda_text._Layer(text, read_by_sdf=True)
            assert layer.lookup(spec_path) == line, spec_path
        assert layer._skeleton
    # A character of more than one byte would shift the skeleton's offsets: tokenized.
    wide = text.replace("# nor this", "# ni ceci é")
    layer = usda_text._Layer(wide, read_by_sdf=True)
    assert [layer.lookup(p) for p in expected] == list(_hostile_lines(wide).values())
    assert layer._skeleton == b""


def _sdf_accepts(text: str) -> bool:
    try:
        return Sdf.Layer.CreateAnonymous(".usda").ImportFromString(text)
    except Exception:  # noqa: BLE001 - Tf errors
        return False


# --- laziness and the cache -------------------------------------------------------------


def _shot(prims: int, line: str) -> str:
    body = "".join(f'    def Mesh "m{i}"\n    {{\n        {line}\n    }}\n' for i in range(prims))
    return f'#usda 1.0\ndef Xform "Geo"\n{{\n{body}}}\ndef Scope "Render"\n{{\n    int x = 1\n}}\n'


def test_a_lookup_reads_only_the_blocks_on_its_way() -> None:
    layer = usda_text._Layer(_shot(200, "float a = 1"))
    assert layer.lookup("/Render.x") == 807
    assert layer.read == {"", "/Render"} and not layer.complete
    assert "/Geo/m0" not in layer.lines


def test_many_lookups_deep_in_large_blocks_end_in_one_full_read() -> None:
    # Each level holds almost all the text: reading one level deeper skips it again.
    depth = 12
    heads = "".join(f'{"    " * i}def Xform "p{i}"\n{"    " * i}{{\n' for i in range(depth))
    body = "".join(f"    float a{i} = {i}\n" for i in range(300))
    text = "#usda 1.0\n" + heads + body + "}\n" * depth
    deepest = "/" + "/".join(f"p{i}" for i in range(depth))
    small = usda_text._Layer(text)
    assert small.lookup("/p0.nothing") is None and not small.complete
    layer = usda_text._Layer(text)
    assert layer.lookup(deepest + ".a299") == 2 * depth + 301
    assert layer.complete
    assert layer.lines == reference_index(text)
    assert layer.spent <= 2 * layer._full_read_cost()


def test_a_layer_of_long_lines_is_read_whole_at_once() -> None:
    text = _shot(3, "float3[] points = [" + "(0, 1e-05, 0), " * 2000 + "(1, 1, 1)]")
    layer = usda_text._Layer(text)
    assert layer.lookup("/Render.x") == 19
    assert layer.complete and layer.lines == reference_index(text)


def test_line_of_reads_a_layer_once_per_lint_and_again_in_the_next(tmp_path: Path) -> None:
    layer = tmp_path / "shot.usda"
    layer.write_text('#usda 1.0\ndef Scope "A"\n{\n    int x = 1\n}\n')
    with lint_cache():
        assert line_of(str(layer), "/A.x") == 4
        layer.write_text('#usda 1.0\n\n\ndef Scope "A"\n{\n    int x = 1\n}\n')
        assert line_of(str(layer), "/A.x") == 4  # the text this lint read first
    with lint_cache():
        assert line_of(str(layer), "/A.x") == 6  # a new lint reads it again
    assert line_of(str(layer), "/A.x") == 6  # outside a lint: read for the lookup
    assert line_of(str(tmp_path / "missing.usda"), "/A") is None


def test_the_lint_cache_holds_each_layer_index_once(tmp_path: Path) -> None:
    layer = tmp_path / "shot.usda"
    layer.write_text(_shot(50, "float a = 1"))
    with lint_cache() as cache:
        assert line_of(str(layer), "/Render.x") == 207
        assert line_of(str(layer), "/Render") is not None
        assert len(cache) == 1


def test_the_skipping_patterns_are_compiled_on_first_use_not_at_import() -> None:
    # Each takes milliseconds to compile; a check with no finding to place never needs
    # them, and placing one in a layer Sdf read needs all but the text-walking ``flat``.
    shot = Path(__file__).resolve().parents[2] / "examples" / "framing_shot" / "shot.usda"
    code = (
        "from usdrender_lint.layers import usda_text as u\n"
        "print(sorted(vars(u._SKIPPERS)))\n"
        "u.index_usda('def \"A\" {\\n}\\n')\n"
        "print(sorted(vars(u._SKIPPERS)))\n"
        f"u.line_of({str(shot)!r}, '/Render/FilmSettings.camera')\n"
        "print(sorted(vars(u._SKIPPERS)))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    at_import, after_text, after_line = out.stdout.splitlines()
    assert (at_import, after_text) == ("[]", "['statement_rest']")
    assert "'skeleton_flat'" in after_line and "'flat'" not in after_line


def test_a_number_with_an_exponent_closes_its_array() -> None:
    # "1e-05]": the word is "e-05", the bracket closes the array (was read as one word,
    # and every spec after it lost its line).
    text = (
        '#usda 1.0\ndef "A"\n{\n    float[] w = [0, 1e-05]\n'
        "    float3[] extent = [(0, 0, 0), (1, 1e+05, 1)]\n"
        '    def "B"\n    {\n        double d = 1E-3\n    }\n}\ndef "C"\n{\n}\n'
    )
    expected = {"/A": 2, "/A.w": 4, "/A.extent": 5, "/A/B": 6, "/A/B.d": 8, "/C": 11}
    assert index_usda(text) == expected
    layer = Sdf.Layer.CreateAnonymous(".usda")
    assert layer.ImportFromString(text)
    listed: list[str] = []
    layer.Traverse("/", lambda path: listed.append(str(path)))
    assert set(expected) == set(listed) - {"/"}


def test_strings_with_escapes_and_braces_are_skipped_whole() -> None:
    # An escaped backslash ends the first string; an escaped quote does not end the second.
    text = '#usda 1.0\ndef Scope "A"\n{\n    string s = "{\\\\"\n    string t = "\\" }"\n}\n'
    text += 'def Scope "B"\n{\n}\n'
    for read_by_sdf in (False, True):
        layer = usda_text._Layer(text, read_by_sdf=read_by_sdf)
        assert (layer.lookup("/B"), layer.lookup("/A.t")) == (7, 5)


_COMPILES_RECORDED = """
import re
compiled = []
compile_now = re.compile
re.compile = lambda pattern, flags=0: compiled.append(pattern) or compile_now(pattern, flags)
from usdrender_lint.layers import usda_text
text = '#usda 1.0\\ndef Scope "A"\\n{\\n    int x = 1  # c\\n}\\n'
layer = usda_text._Layer(text, read_by_sdf=True)
assert layer.lookup("/A.x") == 4
placing = len(compiled)
assert usda_text.comment_lines(layer.text) == [4]
print(r"(?:[ \\t\\r\\f\\v]++|/\\*.*?\\*/)*+" in compiled[:placing], placing < len(compiled))
"""


def test_placing_a_finding_compiles_none_of_the_fixes_patterns() -> None:
    """The statement spans' and comment_lines' patterns (the fixes') are compiled
    at their first use: the import and a line lookup need none of them."""
    proc = subprocess.run(
        [sys.executable, "-c", _COMPILES_RECORDED], capture_output=True, text=True, check=True
    )
    assert proc.stdout.split() == ["False", "True"]
