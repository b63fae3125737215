"""The fixture harness shipped for rule authors (usdrender_lint.testing): the
``# expect:`` line format, what check_fixture asserts, and lint_text."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from usdrender_lint.registry import SelectionError
from usdrender_lint.rules.settings.se003_data_window_malformed import DataWindowMalformed
from usdrender_lint.testing import (
    Expectation,
    ExpectationError,
    check_fixture,
    expectations,
    lint_text,
)

#: One SE003 finding (inverted on x, swappable: a fix) and one SE006 (case slip, a fix).
TWO_WINDOWS = """#usda 1.0
{expect}
def Scope "Render"
{{
    def RenderSettings "A"
    {{
        uniform float4 dataWindowNDC = (0.8, 0, 0.2, 1)
        uniform token aspectRatioConformPolicy = "CROPAPERTURE"
    }}

    def RenderSettings "B"
    {{
        uniform float4 dataWindowNDC = (0, 0, 1, 1)
    }}
}}
"""


def _fixture(tmp_path: Path, *lines: str, name: str = "fail_case.usda") -> Path:
    path = tmp_path / name
    path.write_text(TWO_WINDOWS.format(expect="\n".join(lines)), encoding="utf-8")
    return path


# -- the line format -----------------------------------------------------------------


def test_the_full_form_and_its_defaults_parse(tmp_path: Path) -> None:
    path = _fixture(
        tmp_path,
        '# expect: SE003 </Render/A.dataWindowNDC> x2 nofix "is inverted or empty on x"',
        "#expect: SE006 </Render/A.aspectRatioConformPolicy> fix",
        "# expect: ST001 <>",
        '# expect: CA004 </R.camera> x1 fix "names "quoted" words"',
    )
    assert expectations(path) == [
        Expectation("SE003", "/Render/A.dataWindowNDC", 2, False, "is inverted or empty on x", 2),
        Expectation("SE006", "/Render/A.aspectRatioConformPolicy", None, True, None, 3),
        Expectation("ST001", "", None, None, None, 4),
        Expectation("CA004", "/R.camera", 1, True, 'names "quoted" words', 5),
    ]
    assert [e.full for e in expectations(path)] == [True, False, False, True]


@pytest.mark.parametrize(
    "line",
    [
        "# expect: SE003 /Render/A.dataWindowNDC",  # no angle brackets
        "# expect: SE003 </Render/A.dataWindowNDC> 2",  # count without x
        "# expect: SE003 </Render/A.dataWindowNDC> x0",  # no finding is a pass fixture
        '# expect: SE003 </Render/A.dataWindowNDC> "inverted" nofix',  # out of order
        "# expect: SE003 </Render/A.dataWindowNDC> maybe",
    ],
)
def test_a_line_that_does_not_parse_is_an_error(tmp_path: Path, line: str) -> None:
    path = _fixture(tmp_path, line)
    with pytest.raises(ExpectationError, match=r"fail_case\.usda:2: cannot read"):
        expectations(path)


# -- check_fixture -------------------------------------------------------------------

A = '# expect: SE003 </Render/A.dataWindowNDC> x1 fix "is inverted or empty on x"'


def test_a_fixture_that_states_its_findings_passes(tmp_path: Path) -> None:
    check_fixture(_fixture(tmp_path, A), "SE003")
    check_fixture(_fixture(tmp_path, "# expect: SE003 </Render/A.dataWindowNDC>"), "SE003")
    fixed = '# expect: SE006 </Render/A.aspectRatioConformPolicy> x1 fix "CROPAPERTURE"'
    check_fixture(_fixture(tmp_path, fixed), "SE006")


@pytest.mark.parametrize(
    ("line", "complaint"),
    [
        (A.replace("x1", "x2"), "got 1 matching"),
        (A.replace("fix", "nofix"), "got 0 matching"),
        (A.replace("on x", "on y"), "got 0 matching"),
        (A.replace("A.dataWindowNDC", "B.dataWindowNDC"), "got 0 matching"),
    ],
)
def test_count_fix_fragment_and_path_are_each_asserted(
    tmp_path: Path, line: str, complaint: str
) -> None:
    with pytest.raises(AssertionError, match=complaint) as failure:
        check_fixture(_fixture(tmp_path, line), "SE003")
    # The report names the line and shows what the rule did say there.
    assert "fail_case.usda:2" in str(failure.value)


def test_a_finding_no_line_declares_fails(tmp_path: Path) -> None:
    text = TWO_WINDOWS.format(expect=A).replace("(0, 0, 1, 1)", "(0, 1, 1, 0)")
    path = tmp_path / "fail_case.usda"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(AssertionError, match=r"unexpected SE003 findings: </Render/B"):
        check_fixture(path, "SE003")


def test_two_lines_claiming_the_same_finding_fail(tmp_path: Path) -> None:
    overlapping = A.replace('"is inverted or empty on x"', '"dataWindowNDC"')
    with pytest.raises(AssertionError, match="two lines match the same finding"):
        check_fixture(_fixture(tmp_path, A, overlapping), "SE003")


def test_a_fail_fixture_without_a_line_for_the_code_fails(tmp_path: Path) -> None:
    with pytest.raises(AssertionError, match="must declare"):
        check_fixture(_fixture(tmp_path, "# expect: SE006 </Render/A>"), "SE003")


def test_a_pass_fixture_must_give_no_finding_of_the_code(tmp_path: Path) -> None:
    check_fixture(_fixture(tmp_path, name="pass_case.usda"), "PA001")
    with pytest.raises(AssertionError, match="expected no SE003 finding"):
        check_fixture(_fixture(tmp_path, name="pass_case.usda"), "SE003")


# -- lint_text -----------------------------------------------------------------------


def test_lint_text_lints_a_string() -> None:
    findings = lint_text(TWO_WINDOWS.format(expect=""), select=["SE003"])
    (finding,) = findings
    assert finding.code == "SE003"
    assert finding.location.path == "/Render/A.dataWindowNDC"
    assert (finding.location.file, finding.location.layer) == ("stage.usda", "stage.usda")
    assert finding.location.line == 7


def test_lint_text_selects_among_given_rules() -> None:
    text = TWO_WINDOWS.format(expect="")
    assert {f.code for f in lint_text(text, select=["SE"])} == {"SE003", "SE006", "SE015"}
    assert [f.code for f in lint_text(text, rules=[DataWindowMalformed()])] == ["SE003"]
    # As --select: a selector that matches none of the rules is a mistake, not a silent pass.
    with pytest.raises(SelectionError, match="'SE006' matches no rule"):
        lint_text(text, rules=[DataWindowMalformed()], select=["SE006"])


def test_lint_text_composes_supporting_layers_by_name() -> None:
    root = """#usda 1.0
(
    subLayers = [@./layers/lighting.usda@]
)
over "Render"
{
    over "B"
    {
        uniform float4 dataWindowNDC = (0, 0, 1, 1)
    }
}
"""
    weaker = TWO_WINDOWS.format(expect="").replace("(0, 0, 1, 1)", "(0, 1, 1, 0)")
    findings = lint_text(root, select=["SE003"], layers={"layers/lighting.usda": weaker})
    # A is defined in the sublayer only; B's defect is hidden by the root's opinion.
    (finding,) = findings
    assert finding.location.path == "/Render/A.dataWindowNDC"
    assert finding.location.file == "stage.usda"
    assert finding.location.layer == "layers/lighting.usda"
    assert finding.location.line == 7


def test_lint_text_names_missing_layers_relative_to_its_folder() -> None:
    text = '#usda 1.0\n(\n    subLayers = [@./missing.usda@]\n)\ndef Scope "Render"\n{\n}\n'
    (finding,) = lint_text(text, select=["ST002"], name="shot.usda")
    assert finding.location.file == "shot.usda"
    assert "@missing.usda@" in finding.message
    assert "usdrender-lint-" not in finding.message


@pytest.mark.parametrize("name", ["/tmp/abs.usda", "../outside.usda", "a/../../b.usda", ""])
def test_lint_text_keeps_layers_inside_its_folder(name: str) -> None:
    with pytest.raises(ValueError, match="relative path inside"):
        lint_text("#usda 1.0\n", layers={name: "#usda 1.0\n"})


def test_lint_text_refuses_a_layer_named_like_the_stage() -> None:
    with pytest.raises(ValueError, match="is the stage itself"):
        lint_text("#usda 1.0\n", layers={"stage.usda": "#usda 1.0\n"})


@pytest.mark.parametrize(
    ("code", "said"),
    [
        ("SE0003", "no rule has code 'SE0003' (did you mean SE003?)"),
        ("ZZ999", "no rule has code 'ZZ999' (is its plugin installed?)"),
        ("data-window-malformed", "is the name of SE003; check_fixture takes a rule code"),
    ],
)
def test_a_code_no_rule_has_is_an_error(tmp_path: Path, code: str, said: str) -> None:
    # It used to pass any pass fixture: no finding of a code nothing reports.
    with pytest.raises(ValueError, match=re.escape(said)):
        check_fixture(_fixture(tmp_path, name="pass_case.usda"), code)
    with pytest.raises(ValueError, match=re.escape(said)):
        check_fixture(
            _fixture(tmp_path, name="pass_case.usda"), code, rules=[DataWindowMalformed()]
        )


@pytest.mark.parametrize(
    ("safety", "said"),
    [
        ("none", "SE003 offers fixes (</Render/A.dataWindowNDC> fix"),
        ("safe", "SE003's fix_safety is 'safe' but it offers unsafe fixes"),
    ],
)
def test_fixes_that_contradict_the_rule_fix_safety_fail(
    tmp_path: Path, safety: str, said: str
) -> None:
    # A plugin rule left at fix_safety "none" that offers fixes was listed by
    # `rules` and `explain` as having none; its fixtures passed.
    Mislabelled = type("Mislabelled", (DataWindowMalformed,), {"fix_safety": safety})
    fixture = _fixture(tmp_path, A)
    check_fixture(fixture, "SE003", rules=[DataWindowMalformed()])  # "unsafe", as it offers
    with pytest.raises(AssertionError, match=re.escape(said)):
        check_fixture(fixture, "SE003", rules=[Mislabelled()])


def test_a_renderer_rule_needs_a_profiler_and_a_profile_that_exists(tmp_path: Path) -> None:
    # Without a profiler a renderer rule never runs: every pass fixture of it passed.
    from usdrender_lint.profiles import Profiler

    Karma = type("KarmaOnly", (DataWindowMalformed,), {"profile": "karma"})
    fixture = _fixture(tmp_path, name="pass_case.usda")
    with pytest.raises(ValueError, match=r"SE003 is a rule of the karma profile.*profiler="):
        check_fixture(fixture, "SE003", rules=[Karma()])
    check_fixture(fixture, "SE003", rules=[Karma()], profiler=Profiler())
    Karma.profile = "karma "  # set after the class was defined: its own check did not see it
    with pytest.raises(ValueError, match=r"SE003 \(KarmaOnly\): profile 'karma ' is no renderer"):
        check_fixture(fixture, "SE003", rules=[Karma()], profiler=Profiler())
