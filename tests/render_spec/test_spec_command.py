"""``usdrender-lint spec`` on the command line: the three formats, where they
are written, the documented JSON schema, and bad input handled as check does."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ElementTree
from functools import partial
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.render_spec.compute import SpecOptions, compute_file_spec
from usdrender_lint.render_spec.document import spec_document
from usdrender_lint.render_spec.svg import svg_files
from usdrender_lint.running.inspect import InspectRequest, inspect_files

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
CLEAN = EXAMPLES / "clean_shot" / "shot.usda"
BROKEN = EXAMPLES / "broken_shot" / "shot.usda"
WIP = EXAMPLES / "broken_shot" / "lighting_wip.usda"
FRAMING = EXAMPLES / "framing_shot" / "shot.usda"
DOCS = REPO / "docs"


def run(*args: str, jobs: str = "1"):
    return CliRunner().invoke(cli, ["spec", "--isolated", "--jobs", jobs, *args])


def test_text_view_of_the_clean_shot() -> None:
    result = run(str(CLEAN))
    assert result.exit_code == 0, result.output
    text = result.stdout
    assert "RenderSettings /Render/PrimarySettings  (primary, profile generic)" in text
    assert "RenderProduct /Render/Products/beauty  → renders/shot010_beauty.####.exr" in text
    assert "aperture       36 x 20.25 → 36 x 20.25" in text
    assert "data window    x 0..1919, y 0..1079  (1920 x 1080)" in text
    assert "motion blur    on, shutter -0.25 .. 0.25" in text
    assert "┌" in text and "░" in text  # the framing is drawn beside the values
    assert "\x1b[" not in text  # not a terminal: plain


def test_text_view_flags_what_the_linter_reports() -> None:
    result = run(str(BROKEN))
    assert result.exit_code == 0, result.output
    text = result.stdout
    assert "no camera" in text and "empty data window" in text  # inside the drawing
    assert "[</World/cropCam> does not exist on the composed stage; CA003]" in text
    assert "NDC (0.75, 0.25, 0.25, 0.75)  [SE003]" in text
    assert "drops the product: could not find camera </World/cropCam>" in text


def test_text_view_names_the_findings_on_no_settings_or_product(tmp_path: Path) -> None:
    # ST003 (the stage's metadata) and ST009 (a RenderVar nothing reaches) are
    # on no settings or product: the JSON listed them, the text view did not.
    shot = tmp_path / "shot.usda"
    shot.write_text(
        "#usda 1.0\n"
        'def Scope "Render"\n{\n'
        '    def RenderSettings "settings"\n    {\n'
        "        uniform int2 resolution = (64, 64)\n    }\n"
        '    def RenderVar "stray"\n    {\n'
        '        uniform string sourceName = "Ci"\n    }\n'
        "}\n"
    )
    as_json = json.loads(run(str(shot), "--format", "json").stdout)
    assert {"ST003", "ST009"} <= set(as_json["files"][0]["findings"])
    result = run(str(shot))
    assert result.exit_code == 0, result.output
    assert "findings elsewhere in the file: ST003, ST009  (check lists them)" in result.stdout


def test_a_folder_without_usd_files_is_said_as_check_says_it(tmp_path: Path) -> None:
    # spec printed nothing at all and exited 0, as if the folder had been read.
    (tmp_path / "notes.txt").write_text("not a layer\n")
    result = run(str(tmp_path))
    said = f"usdrender-lint: warning: {tmp_path}: no USD files (.usd, .usda, .usdc, .usdz) in it\n"
    assert (result.exit_code, result.stdout, result.stderr) == (0, "", said)
    check = CliRunner().invoke(cli, ["check", "--isolated", str(tmp_path)])
    assert said in check.stderr


def test_json_document_follows_its_schema(tmp_path: Path) -> None:
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads((DOCS / "spec-schema.json").read_text())
    result = run("--format", "json", str(EXAMPLES), str(tmp_path / "missing.usda"))
    assert result.exit_code == 2
    document = json.loads(result.stdout)
    jsonschema.Draft202012Validator(schema).validate(document)
    assert document["schema_version"] == 1
    statuses = {Path(f["file"]).name + ":" + f["status"] for f in document["files"]}
    assert {"lighting_wip.usda:error", "missing.usda:error", "shot.usda:computed"} <= statuses


def test_bad_input_is_one_line_each_and_the_others_are_still_computed(tmp_path: Path) -> None:
    missing = tmp_path / "nope.usda"
    result = run("--format", "json", str(missing), str(WIP), str(CLEAN))
    assert result.exit_code == 2
    assert "Traceback" not in result.output + result.stderr
    errors = [line for line in result.stderr.splitlines() if line]
    assert errors == [
        f"usdrender-lint: error: {missing}: no such file",
        f"usdrender-lint: error: {WIP}:9:1: Expected }} at '' in </Lights/key>",
    ]
    files = {f["file"]: f for f in json.loads(result.stdout)["files"]}
    assert files[str(CLEAN)]["status"] == "computed"
    assert files[str(CLEAN)]["settings"][0]["products"]
    assert files[str(WIP)]["status"] == "error"


def test_worker_processes_give_the_same_document() -> None:
    one = run("--format", "json", str(CLEAN), str(BROKEN))
    two = run("--format", "json", str(CLEAN), str(BROKEN), jobs="2")
    assert one.exit_code == two.exit_code == 0
    assert json.loads(one.stdout) == json.loads(two.stdout)


def test_settings_that_do_not_exist_are_an_error_for_that_file() -> None:
    result = run("--settings", "/Render/Nope", str(CLEAN))
    assert result.exit_code == 2
    assert result.stderr == (
        f"usdrender-lint: error: {CLEAN}: no usable RenderSettings at </Render/Nope>\n"
    )


@pytest.mark.parametrize("time", ["soon", "nan"])
def test_a_bad_time_is_a_usage_error(time: str) -> None:
    result = run("--time", time, str(CLEAN))
    assert result.exit_code == 2
    assert "--time" in result.stderr and "Traceback" not in result.stderr


def test_standard_input_is_refused_in_one_line() -> None:
    result = CliRunner().invoke(cli, ["spec", "-"], input="#usda 1.0\n")
    assert result.exit_code == 2
    assert result.stderr == (
        "usdrender-lint: error: spec reads files, not standard input ('-'): save the layer first\n"
    )


def test_svg_needs_a_folder(tmp_path: Path) -> None:
    result = run("--format", "svg", str(CLEAN))
    assert result.exit_code == 2
    assert result.stderr == (
        "usdrender-lint: error: --format svg writes one file per product: give --output DIR\n"
    )
    a_file = tmp_path / "taken"
    a_file.write_text("")
    result = run("--format", "svg", "--output", str(a_file), str(CLEAN))
    assert result.exit_code == 2
    assert "needs a folder, and this is a file" in result.stderr


def test_svg_writes_one_picture_per_product(tmp_path: Path) -> None:
    out = tmp_path / "pictures"
    result = run("--format", "svg", "--output", str(out), str(BROKEN))
    assert result.exit_code == 0, result.output
    names = sorted(p.name for p in out.iterdir())
    assert names == [
        "shot.PrimarySettings.beauty.svg",
        "shot.PrimarySettings.crop.svg",
        "shot.PrimarySettings.utility.svg",
    ]
    assert result.stdout.splitlines() == [str(out / n) for n in names]
    crop = (out / "shot.PrimarySettings.crop.svg").read_text()
    root = ElementTree.fromstring(crop)  # well-formed XML
    assert root.tag == "{http://www.w3.org/2000/svg}svg"
    red = [e.text for e in root.iter() if e.get("fill") == "#cf222e"]
    assert "no camera" in red and "empty data window" in red
    assert any("CA003" in (t or "") for t in red)


def test_svg_names_stay_apart_for_files_of_one_name(tmp_path: Path) -> None:
    result = run("--format", "svg", "--output", str(tmp_path), str(CLEAN), str(BROKEN))
    assert result.exit_code == 0
    names = {p.name for p in tmp_path.iterdir()}
    assert any(n.startswith(f"{_slug(CLEAN)}.") for n in names)
    assert any(n.startswith(f"{_slug(BROKEN)}.") for n in names)
    assert len(names) == 5


def _slug(path: Path) -> str:
    return str(path.with_suffix("")).replace("/", "_").strip("_")


def test_a_settings_without_products_is_pictured_by_its_own_values(tmp_path: Path) -> None:
    layer = tmp_path / "lonely.usda"
    layer.write_text(
        '#usda 1.0\ndef Camera "cam" {\n}\n'
        'def RenderSettings "settings" {\n    rel camera = </cam>\n}\n'
    )
    result = run("--format", "svg", "--output", str(tmp_path / "out"), str(layer))
    assert result.exit_code == 0
    (picture,) = (tmp_path / "out").iterdir()
    assert picture.name == "lonely.settings.svg"
    assert "no products: the settings' own values" in picture.read_text()
    text = run(str(layer)).stdout
    assert "no products: the application decides the outputs" in text


@pytest.mark.parametrize("output_format", ["json", "text"])
def test_output_file_is_written_instead_of_stdout(tmp_path: Path, output_format: str) -> None:
    target = tmp_path / f"spec.{output_format}"
    result = run("--format", output_format, "--output", str(target), str(CLEAN))
    assert result.exit_code == 0
    assert result.stdout == ""
    written = target.read_text()
    if output_format == "json":
        assert json.loads(written)["files"][0]["status"] == "computed"
    else:
        assert "RenderProduct /Render/Products/beauty" in written and "\x1b[" not in written


def test_unwritable_output_is_one_line(tmp_path: Path) -> None:
    (tmp_path / "a_file").write_text("")
    target = tmp_path / "a_file" / "spec.json"  # a missing folder would be created
    result = run("--format", "json", "--output", str(target), str(CLEAN))
    assert result.exit_code == 2
    assert result.stderr.startswith(f"usdrender-lint: error: {target}: cannot write")
    assert len(result.stderr.splitlines()) == 1


def test_the_readme_pictures_are_current(monkeypatch: pytest.MonkeyPatch) -> None:
    """docs/spec/ holds what ``spec --format svg`` draws for the framing example
    today (regenerate: usdrender-lint spec --isolated --format svg --output
    docs/spec examples/framing_shot/shot.usda)."""
    monkeypatch.chdir(REPO)
    request = InspectRequest(("examples/framing_shot/shot.usda",), isolated=True, jobs=1, timeout=0)
    (result,) = inspect_files(request, partial(compute_file_spec, options=SpecOptions())).results
    document = spec_document([(result, result.value)], "0")
    committed = {p.name: p.read_text() for p in (DOCS / "spec").glob("*.svg")}
    assert dict(svg_files(document)) == committed


def test_the_guides_text_view_is_current(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every line of the spec guide's (abridged) text view is a line ``spec`` prints."""
    readme = (REPO / "docs" / "guides" / "spec.md").read_text(encoding="utf-8")
    intro = readme.index("The text view of `examples/framing_shot/shot.usda`")
    start = readme.index("```text\n", intro) + len("```text\n")
    shown = readme[start : readme.index("```", start)].splitlines()
    monkeypatch.chdir(REPO)
    printed = run("examples/framing_shot/shot.usda").stdout.splitlines()
    assert [line for line in shown if line not in printed] == []


def test_the_legend_of_a_tall_picture_is_whole(tmp_path: Path) -> None:
    # A square image draws narrower than the legend; the legend stays whole
    # and the values stay in one column.
    path = tmp_path / "square.usda"
    path.write_text(
        "#usda 1.0\n"
        'def Camera "cam"\n{\n    float horizontalAperture = 24\n'
        "    float verticalAperture = 24\n}\n"
        'def RenderSettings "settings"\n{\n    rel camera = </cam>\n'
        "    rel products = </p>\n    uniform int2 resolution = (100, 100)\n}\n"
        'def RenderProduct "p"\n{\n}\n'
    )
    result = run(str(path))
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert any(line.startswith("  ─ image   · camera aperture ") for line in lines)
    value_columns = {line.index("camera ") for line in lines if "camera         /cam" in line}
    assert value_columns == {
        line.index("time ") for line in lines if "time           Default" in line
    }


@pytest.mark.parametrize("width", [60, 80, 100])
def test_a_narrow_terminal_gets_the_values_under_the_drawing(width: int) -> None:
    # Side by side the rows are wider than 80 columns: the terminal would
    # wrap each one through the drawing.
    from usdrender_lint.paths import columns
    from usdrender_lint.render_spec.textview import document_lines

    request = InspectRequest((str(CLEAN),), isolated=True, jobs=1, timeout=0)
    (result,) = inspect_files(request, partial(compute_file_spec, options=SpecOptions())).results
    document = spec_document([(result, result.value)], "0")
    lines = ["".join(text for text, _ in line) for line in document_lines(document, width)]
    side_by_side = ["".join(text for text, _ in line) for line in document_lines(document)]
    drawing_rows = [line for line in lines if "│" in line]
    assert drawing_rows and all(columns(line.rstrip()) <= width for line in drawing_rows)
    if all(columns(line) <= width for line in side_by_side):
        assert lines == side_by_side  # room enough: beside it, as piped
    else:
        assert any(line.startswith("  data window    x 0..1919") for line in lines)
