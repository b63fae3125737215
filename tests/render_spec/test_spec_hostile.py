"""``spec`` on hostile input (issue 31, item 5): near linear in the number of
products, pictures of apertures that cannot be drawn, names that are not UTF-8
and values holding control characters. Costs are compared as counts of Python
calls (the same on a loaded machine), never as times."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from functools import partial
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.render_spec.compute import SpecOptions, compute_file_spec
from usdrender_lint.render_spec.document import spec_document
from usdrender_lint.running.inspect import InspectRequest, inspect_files


def _products(count: int) -> str:
    """One RenderSettings with ``count`` products, each reported at the
    settings by a finding that names it (CA006: 'settings ... with product')."""
    targets = ", ".join(f"</Render/P{i}>" for i in range(count))
    products = "".join(
        f'    def RenderProduct "P{i}"\n    {{\n        token productName = "p{i}.exr"\n'
        "        rel orderedVars = </Render/V>\n    }\n"
        for i in range(count)
    )
    return (
        '#usda 1.0\ndef Camera "Cam"\n{\n    float horizontalAperture = 36\n'
        '    float verticalAperture = 24\n}\ndef Scope "Render"\n{\n'
        '    def RenderSettings "S"\n    {\n        rel camera = </Cam>\n'
        f"        rel products = [{targets}]\n    }}\n{products}"
        '    def RenderVar "V"\n    {\n        string sourceName = "Ci"\n    }\n}\n'
    )


def _calls(path: Path) -> int:
    """Python and C calls made computing and writing the file's specification."""
    calls = 0

    def count(frame: object, event: str, arg: object) -> None:
        nonlocal calls
        calls += 1

    request = InspectRequest((str(path),), isolated=True, jobs=1, timeout=0)
    sys.setprofile(count)
    try:
        inspection = inspect_files(request, partial(compute_file_spec, options=SpecOptions()))
        spec_document([(r, r.value) for r in inspection.results], "0")  # type: ignore[attr-defined]
    finally:
        sys.setprofile(None)
    return calls


def test_spec_is_near_linear_in_the_products(tmp_path: Path) -> None:
    """Each product matched every message against every product: cubic, 1,000
    products took 329 s of CPU. Four times the products: about four times the
    calls (it was about 60 times)."""
    small, large = tmp_path / "small.usda", tmp_path / "large.usda"
    small.write_text(_products(100))
    large.write_text(_products(400))
    _calls(small)  # imports and first-use caches out of the count
    ratio = _calls(large) / _calls(small)
    assert ratio < 6, ratio


def test_products_get_the_findings_that_name_them_and_no_other(tmp_path: Path) -> None:
    (tmp_path / "shot.usda").write_text(_products(12))
    result = CliRunner().invoke(
        cli, ["spec", "--isolated", "-j", "1", "--format", "json", str(tmp_path / "shot.usda")]
    )
    settings = json.loads(result.stdout)["files"][0]["settings"][0]
    # P1 is named by its own CA006, not by P10's or P11's (a longer path it prefixes).
    assert [p["findings"] for p in settings["products"]] == [["CA006"]] * 12


CAMERA = """#usda 1.0
def Camera "Cam"
{{
    float horizontalAperture = {0}
    float verticalAperture = {1}
    float horizontalApertureOffset = {2}
    float verticalApertureOffset = {3}
}}
def Scope "Render"
{{
    def RenderSettings "S"
    {{
        rel camera = </Cam>
        rel products = </Render/P>
    }}
    def RenderProduct "P"
    {{
        token productName = "p.exr"
    }}
}}
"""


@pytest.mark.parametrize(
    "aperture",
    [(0, 0, 0, 0), (0, 24, 0, 0), (36, 24, 1e30, 0), (36, 24, 3e38, -3e38)],
    ids=["zero", "zero-width", "huge-offset", "huger-offsets"],
)
def test_svg_of_an_aperture_that_cannot_be_drawn(tmp_path: Path, aperture: tuple) -> None:
    """Each was 'internal error: ZeroDivisionError'."""
    (tmp_path / "shot.usda").write_text(CAMERA.format(*aperture))
    out = tmp_path / "pictures"
    result = CliRunner().invoke(
        cli,
        [
            "spec",
            "--isolated",
            "-j",
            "1",
            "--format",
            "svg",
            "--output",
            str(out),
            str(tmp_path / "shot.usda"),
        ],
    )
    assert result.exit_code == 0, result.output
    (picture,) = out.iterdir()
    ElementTree.parse(picture)  # well-formed


def _spec(folder: Path, *args: str | bytes) -> subprocess.CompletedProcess[bytes]:
    return subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "spec", "--isolated", *args],
        capture_output=True,
        cwd=folder,
        timeout=300,
    )


def test_a_name_that_is_not_utf8_in_every_view(tmp_path: Path) -> None:
    """Text wrote the raw byte, SVG was 'internal error: UnicodeEncodeError'
    and JSON held a lone surrogate (\\udcff) no strict reader accepts."""
    name = b"n\xffm.usda"
    try:
        with open(os.path.join(os.fsencode(tmp_path), name), "wb") as stream:
            stream.write(CAMERA.format(36, 24, 0, 0).encode())
    except OSError:
        pytest.skip("this file system keeps only UTF-8 names")
    text = _spec(tmp_path, name)
    assert text.returncode == 0 and text.stdout.decode("utf-8").startswith("n\\xffm.usda  at ")
    document = _spec(tmp_path, "--format", "json", name)
    assert document.returncode == 0
    assert json.loads(document.stdout.decode("utf-8"))["files"][0]["file"] == "n\\xffm.usda"
    svg = _spec(tmp_path, "--format", "svg", "--output", "pictures", name)
    assert svg.returncode == 0, svg.stderr
    (picture,) = (tmp_path / "pictures").iterdir()
    assert "n\\xffm.usda" in picture.read_text(encoding="utf-8")
    ElementTree.parse(picture)


def test_control_characters_in_values_are_escaped_in_the_views(tmp_path: Path) -> None:
    (tmp_path / "shot.usda").write_text(
        CAMERA.format(36, 24, 0, 0).replace('"p.exr"', '"p\\x1b]0;pwned\\x07.exr"')
    )
    text = CliRunner().invoke(cli, ["spec", "--isolated", "-j", "1", str(tmp_path / "shot.usda")])
    assert "\x1b" not in text.stdout and "p\\x1b]0;pwned\\x07.exr" in text.stdout
    out = tmp_path / "pictures"
    CliRunner().invoke(
        cli,
        [
            "spec",
            "--isolated",
            "-j",
            "1",
            "--format",
            "svg",
            "--output",
            str(out),
            str(tmp_path / "shot.usda"),
        ],
    )
    (picture,) = out.iterdir()
    ElementTree.parse(picture)  # a raw control character is not XML
    document = CliRunner().invoke(
        cli, ["spec", "--isolated", "-j", "1", "--format", "json", str(tmp_path / "shot.usda")]
    )
    product = json.loads(document.stdout)["files"][0]["settings"][0]["products"][0]
    assert product["name"] == "p\x1b]0;pwned\x07.exr"  # JSON keeps the value whole


def test_an_infinite_value_is_not_shown_as_nan(tmp_path: Path) -> None:
    # The JSON document holds NaN and infinities as null; the views said "nan"
    # for an authored inf, and "no pixels at this resolution" for 100 x 100.
    (tmp_path / "shot.usda").write_text(
        "#usda 1.0\n"
        'def Camera "cam"\n{\n    float horizontalAperture = 36\n'
        "    float verticalAperture = 24\n}\n"
        'def RenderSettings "settings"\n{\n    rel camera = </cam>\n    rel products = </p>\n'
        "    uniform int2 resolution = (100, 100)\n    uniform float pixelAspectRatio = inf\n"
        "    uniform float4 dataWindowNDC = (-inf, 0, 1, 1)\n}\n"
        'def RenderProduct "p"\n{\n}\n'
    )
    out = tmp_path / "pictures"
    runner = CliRunner()
    text = runner.invoke(cli, ["spec", "--isolated", "-j", "1", str(tmp_path / "shot.usda")])
    assert text.exit_code == 0, text.output
    assert "nan" not in text.stdout
    assert "pixel aspect   not finite  [SE002]" in text.stdout
    assert "(not finite, 0, 1, 1)  a bound is not finite" in text.stdout
    args = ["spec", "--isolated", "-j", "1", "--format", "svg", "--output", str(out)]
    svg = runner.invoke(cli, [*args, str(tmp_path / "shot.usda")])
    assert svg.exit_code == 0, svg.output
    (picture,) = out.iterdir()
    assert "nan" not in picture.read_text()


def test_a_data_window_with_an_infinite_bound_is_null_as_documented(tmp_path: Path) -> None:
    (tmp_path / "shot.usda").write_text(
        "#usda 1.0\n"
        'def RenderSettings "settings"\n{\n    rel products = </p>\n'
        "    uniform int2 resolution = (100, 100)\n"
        "    uniform float4 dataWindowNDC = (0, 0, inf, 1)\n}\n"
        'def RenderProduct "p"\n{\n}\n'
    )
    args = ["spec", "--isolated", "-j", "1", "--format", "json", str(tmp_path / "shot.usda")]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 0, result.output
    (product,) = json.loads(result.stdout)["files"][0]["settings"][0]["products"]
    assert product["dataWindowNDC"] == [0.0, 0.0, None, 1.0]
    assert product["dataWindow"] is None
    page = (Path(__file__).resolve().parents[2] / "docs/reference/spec-json.md").read_text()
    (row,) = [line for line in page.splitlines() if line.startswith("| `products[].dataWindow` |")]
    assert row.endswith(
        "null when the resolution has no pixels or a bound of `dataWindowNDC` is not finite |"
    )


def test_a_control_character_in_a_var_is_escaped_once_in_the_text_view(tmp_path: Path) -> None:
    """The document's strings are escaped for printing; the view quoted the
    sourceName with repr, which doubled the backslash (ESC showed as \\\\x1b,
    a backslash followed by 'x1b')."""
    shot = CAMERA.format(36, 24, 0, 0).replace(
        'token productName = "p.exr"',
        'token productName = "p.exr"\n        rel orderedVars = </Render/V>',
    )
    shot = (
        shot.rstrip()[:-1]
        + '    def RenderVar "V"\n    {\n        string sourceName = "C\\x1bi"\n    }\n}\n'
    )
    (tmp_path / "shot.usda").write_text(shot)
    text = CliRunner().invoke(cli, ["spec", "--isolated", "-j", "1", str(tmp_path / "shot.usda")])
    assert text.exit_code == 0, text.output
    (line,) = [line for line in text.stdout.splitlines() if "vars" in line]
    assert line.split("vars", 1)[1].split() == ["V", "'C\\x1bi'", "raw", "color3f"]


@pytest.mark.skipif(os.name == "nt", reason="Windows file names hold no control character")
def test_a_picture_is_named_after_a_file_with_a_control_character(tmp_path: Path) -> None:
    """The name is escaped for printing (\\x07) before the picture is named;
    the backslash of the escape was taken for a folder's end, and the
    picture of shot<BEL>.usda was named x07.S.P.svg."""
    (tmp_path / "shot\x07.usda").write_text(CAMERA.format(36, 24, 0, 0))
    done = _spec(tmp_path, "--format", "svg", "--output", "pictures", "shot\x07.usda")
    assert done.returncode == 0, done.stderr
    assert [p.name for p in (tmp_path / "pictures").iterdir()] == ["shot_x07.S.P.svg"]
