"""fixing.text_edits: a fix's change to a layer, spliced into the layer's own
text. Each case edits a layer through Sdf as a fix does and checks the text
that comes out: only the bytes the change needs differ."""

from __future__ import annotations

import pytest
from pxr import Gf, Sdf, Usd, Vt

from usdrender_lint.fixing.text_edits import (
    CannotEdit,
    _Edit,
    apply_edits,
    canonical,
    edit_text,
    indent_unit,
)

SHOT = """#usda 1.0  # shot 42
(
    defaultPrim = "Render"  # for references
)

# The render setup.
def Scope "Render"
{
  def RenderSettings "Settings" (
      doc = "main"
  )
  {
      bool instantaneousShutter = true   # to go
      uniform token[] materialBindingPurposes = ["full",   "allPurpose"]{TRAILING}
      uniform float4 dataWindowNDC = (0.80, 0.0, 0.20, 1.0)
      rel camera = </World/rig>
      uniform int2 resolution = (1920, 1080)

      def RenderProduct "P" {}
  }
}
""".replace("{TRAILING}", "  ")  # trailing spaces stay too


def fixed(text: str, fix) -> str:
    """``text`` after ``fix(stage)`` edits its layer, as --fix writes it."""
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(text)
    before = layer.ExportToString()
    fix(Usd.Stage.Open(layer))
    after = layer.ExportToString()
    new = edit_text(text, before, after)
    assert canonical(new) == after
    return new


def changed_lines(old: str, new: str) -> list[tuple[str, str]]:
    """The lines that differ, pairwise (the cases below keep the line count)."""
    pairs = zip(old.split("\n"), new.split("\n"), strict=True)
    return [(a, b) for a, b in pairs if a != b]


def settings(stage: Usd.Stage) -> Usd.Prim:
    return stage.GetPrimAtPath("/Render/Settings")


def test_a_value_changes_and_nothing_else() -> None:
    def fix(stage):
        settings(stage).GetAttribute("materialBindingPurposes").Set(Vt.TokenArray(["full", ""]))

    new = fixed(SHOT, fix)
    # One element; its neighbours' spacing, the trailing spaces, every comment stay.
    assert changed_lines(SHOT, new) == [
        (
            '      uniform token[] materialBindingPurposes = ["full",   "allPurpose"]  ',
            '      uniform token[] materialBindingPurposes = ["full",   ""]  ',
        )
    ]


def test_a_tuple_changes_element_by_element_keeping_their_spelling() -> None:
    def fix(stage):
        attr = settings(stage).GetAttribute("dataWindowNDC")
        xmin, ymin, xmax, ymax = attr.Get()
        attr.Set(type(attr.Get())(xmax, ymin, xmin, ymax))

    new = fixed(SHOT, fix)
    assert changed_lines(SHOT, new) == [
        (
            "      uniform float4 dataWindowNDC = (0.80, 0.0, 0.20, 1.0)",
            "      uniform float4 dataWindowNDC = (0.2, 0.0, 0.8, 1.0)",
        )
    ]


def test_a_removed_and_an_added_property_share_the_line_and_its_comment() -> None:
    def fix(stage):
        prim = settings(stage)
        prim.RemoveProperty("instantaneousShutter")
        prim.CreateAttribute(
            "disableMotionBlur", Sdf.ValueTypeNames.Bool, variability=Sdf.VariabilityUniform
        ).Set(True)

    new = fixed(SHOT, fix)
    # The file spells booleans true/false, so the new value does too.
    assert changed_lines(SHOT, new) == [
        (
            "      bool instantaneousShutter = true   # to go",
            "      uniform bool disableMotionBlur = true   # to go",
        )
    ]


def test_a_removed_property_leaves_its_comment() -> None:
    new = fixed(SHOT, lambda stage: settings(stage).RemoveProperty("instantaneousShutter"))
    assert "      # to go\n" in new
    assert new.replace("      # to go\n", "") == SHOT.replace(
        "      bool instantaneousShutter = true   # to go\n", ""
    )


def test_a_whole_removed_line_goes() -> None:
    new = fixed(SHOT, lambda stage: settings(stage).RemoveProperty("resolution"))
    assert new == SHOT.replace("      uniform int2 resolution = (1920, 1080)\n", "")


PURPOSES = """#usda 1.0
def RenderSettings "S"
{
    uniform token[] includedPurposes = [
        "render",  # beauty
        "proxy",   # layout
        "render"   # repeated
    ]
    uniform token[] materialBindingPurposes = [
        "full",  # final look
        "preview",  # viewport
        "full"
    ]
    custom string[] notes = [
        "a",  # one
        "b", # two
        "c"  # three
    ]
}
"""


@pytest.mark.parametrize("newline", ["\n", "\r\n"])
def test_removed_array_elements_leave_every_comment_in_place(newline: str) -> None:
    """Removing an element took the comments between it and its neighbour
    along: the comment of the element kept went, that of the one removed moved
    onto the one kept."""

    def fix(stage):
        prim = stage.GetPrimAtPath("/S")
        prim.GetAttribute("includedPurposes").Set(Vt.TokenArray(["render", "proxy"]))
        prim.GetAttribute("materialBindingPurposes").Set(Vt.TokenArray(["full", "preview"]))
        prim.GetAttribute("notes").Set(Vt.StringArray(["a", "c"]))

    new = fixed(PURPOSES.replace("\n", newline), fix)
    assert new == FIXED_PURPOSES.replace("\n", newline)


FIXED_PURPOSES = """#usda 1.0
def RenderSettings "S"
{
    uniform token[] includedPurposes = [
        "render",  # beauty
        "proxy"   # layout
        # repeated
    ]
    uniform token[] materialBindingPurposes = [
        "full",  # final look
        "preview"  # viewport
    ]
    custom string[] notes = [
        "a",  # one
        # two
        "c"  # three
    ]
}
"""


def test_a_new_property_follows_the_file_indentation_after_the_last_property() -> None:
    def fix(stage):
        settings(stage).CreateAttribute(
            "aspectRatioConformPolicy", Sdf.ValueTypeNames.Token, variability=Sdf.VariabilityUniform
        ).Set("expandAperture")

    new = fixed(SHOT, fix)
    added = '      uniform token aspectRatioConformPolicy = "expandAperture"\n'
    anchor = "      uniform int2 resolution = (1920, 1080)\n"
    assert new == SHOT.replace(anchor, anchor + added)


@pytest.mark.parametrize("unit", ["  ", "\t", "   "])
def test_new_text_uses_the_file_indentation_unit(unit: str) -> None:
    product = f'{unit}def RenderProduct "P"\n{unit}{{\n{unit}}}\n'
    text = f'#usda 1.0\n\ndef Scope "Render"\n{{\n{product}}}\n'

    def fix(stage):
        prim = stage.GetPrimAtPath("/Render/P")
        prim.CreateAttribute("productName", Sdf.ValueTypeNames.Token).Set("p.exr")

    new = fixed(text, fix)
    assert f'{unit}{{\n{unit * 2}token productName = "p.exr"\n{unit}}}\n' in new
    assert indent_unit(text) == unit


def test_a_one_line_empty_body_is_opened() -> None:
    def fix(stage):
        stage.GetPrimAtPath("/Render/Settings/P").CreateAttribute(
            "productName", Sdf.ValueTypeNames.Token
        ).Set("p.exr")

    new = fixed(SHOT, fix)
    opened = '"P" {\n          token productName = "p.exr"\n      }'
    assert new == SHOT.replace('"P" {}', opened)


def test_layer_metadata_goes_into_the_existing_block() -> None:
    new = fixed(SHOT, lambda stage: stage.SetMetadata("renderSettingsPrimPath", "/Render/S"))
    anchor = '    defaultPrim = "Render"  # for references\n'
    assert new == SHOT.replace(anchor, anchor + '    renderSettingsPrimPath = "/Render/S"\n')


def test_layer_metadata_without_a_block_comes_after_the_header_and_its_comment() -> None:
    text = '#usda 1.0  # exported by hand\n\ndef Scope "Render"\n{\n}\n'
    new = fixed(text, lambda stage: stage.SetMetadata("renderSettingsPrimPath", "/Render/S"))
    assert new == (
        "#usda 1.0  # exported by hand\n"
        '(\n    renderSettingsPrimPath = "/Render/S"\n)\n'
        '\ndef Scope "Render"\n{\n}\n'
    )


def test_a_metadata_entry_changes_inside_a_dictionary() -> None:
    text = """#usda 1.0

def Scope "Render" (
    customData = {
        int keep = 1  # ours
        dictionary usdrender_lint = {
            string[] ignore = ["SE003", "SE999"]
        }
    }
    kind = "group"
)
{
}
"""

    def fix(stage):
        prim = stage.GetPrimAtPath("/Render")
        prim.SetCustomDataByKey("usdrender_lint:ignore", Vt.StringArray(["SE003"]))

    new = fixed(text, fix)
    assert changed_lines(text, new) == [
        (
            '            string[] ignore = ["SE003", "SE999"]',
            '            string[] ignore = ["SE003"]',
        )
    ]


def test_a_prim_type_change_touches_only_the_type() -> None:
    new = fixed(SHOT, lambda stage: settings(stage).SetTypeName("RenderPass"))
    assert changed_lines(SHOT, new) == [
        ('  def RenderSettings "Settings" (', '  def RenderPass "Settings" (')
    ]


def test_a_moved_prim_keeps_its_own_text() -> None:
    text = """#usda 1.0

def Xform "World"
{
    # The settings, in the wrong place.
    def RenderSettings "Settings"
    {
        int2 resolution = (1920, 1080)  # HD
    }
}

def Scope "Render"
{
}
"""

    def fix(stage):
        editor = Usd.NamespaceEditor(stage)
        assert editor.MovePrimAtPath("/World/Settings", "/Render/Settings")
        assert editor.ApplyEdits()

    new = fixed(text, fix)
    assert "int2 resolution = (1920, 1080)  # HD" in new
    assert "    # The settings, in the wrong place.\n" in new  # the comment stays
    assert 'def Scope "Render"\n{\n    def RenderSettings "Settings"\n' in new


def test_crlf_line_ends_are_kept_and_used() -> None:
    text = SHOT.replace("\n", "\r\n")

    def fix(stage):
        settings(stage).CreateAttribute("pixelAspectRatio", Sdf.ValueTypeNames.Float).Set(2.0)

    new = fixed(text, fix)
    assert "\n" not in new.replace("\r\n", "")
    assert "      uniform float pixelAspectRatio = 2\r\n" in new


@pytest.mark.parametrize(("most", "few"), [("\n", "\r\n"), ("\r\n", "\n")])
def test_new_lines_take_the_line_end_most_lines_have(most: str, few: str) -> None:
    """One line pasted from another system (a CRLF comment in an LF file) made
    every new line CRLF."""
    text = SHOT.replace("\n", most).replace(
        f"# The render setup.{most}", f"# The render setup.{few}"
    )

    def fix(stage):
        settings(stage).CreateAttribute("pixelAspectRatio", Sdf.ValueTypeNames.Float).Set(2.0)

    new = fixed(text, fix)
    assert f"      uniform float pixelAspectRatio = 2{most}" in new
    assert new.count("\r\n") == text.count("\r\n") + (most == "\r\n")


def test_a_file_without_a_final_line_end_keeps_it_so() -> None:
    text = SHOT.rstrip("\n")
    new = fixed(text, lambda stage: settings(stage).GetAttribute("resolution").Set(Gf.Vec2i(1, 1)))
    assert not new.endswith("\n")


def test_overlapping_edits_are_refused() -> None:
    with pytest.raises(CannotEdit, match="overlap"):
        apply_edits("abcdef", [_Edit(0, 3, 0, "x"), _Edit(2, 4, 1, "y")])


def test_a_change_the_text_does_not_have_is_refused() -> None:
    # ``before`` claims a property the text lacks: nothing can be placed.
    text = '#usda 1.0\n\ndef Scope "A"\n{\n}\n'
    before = '#usda 1.0\n\ndef Scope "A"\n{\n    float x = 1\n}\n\n'
    after = '#usda 1.0\n\ndef Scope "A"\n{\n    float x = 2\n}\n\n'
    with pytest.raises(CannotEdit, match="no statement for property 'x'"):
        edit_text(text, before, after)


def test_nothing_to_change_returns_the_text_itself() -> None:
    assert edit_text(SHOT, "x", "x") is SHOT


@pytest.mark.parametrize(
    ("header", "expected"),
    [
        # The bracket closes on the statement's line: the new one goes between them.
        (
            '( defaultPrim = "Render" )',
            '( defaultPrim = "Render"\n    renderSettingsPrimPath = "/Render/S" )',
        ),
        (
            '( defaultPrim = "Render"; upAxis = "Y" )',
            '( defaultPrim = "Render"; upAxis = "Y"\n    renderSettingsPrimPath = "/Render/S" )',
        ),
        # A comment after the statement stays on its line, the new one after it.
        (
            '(\n    defaultPrim = "Render"  # main\n)',
            '(\n    defaultPrim = "Render"  # main\n    renderSettingsPrimPath = "/Render/S"\n)',
        ),
    ],
)
def test_a_statement_added_beside_one_on_a_line_with_its_bracket(
    header: str, expected: str
) -> None:
    """ST003's fix of a header written on one line (the edited text did not
    read back: the statement went after the closing bracket)."""
    body = 'def Scope "Render"\n{\n    def RenderSettings "S"\n    {\n    }\n}\n'
    text = f"#usda 1.0\n{header}\n\n{body}"

    def fix(stage):
        stage.SetMetadata("renderSettingsPrimPath", "/Render/S")

    assert fixed(text, fix) == text.replace(header, expected)
