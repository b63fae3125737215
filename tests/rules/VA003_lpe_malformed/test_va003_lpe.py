"""The LPE parser (rules/_lpe.py) and VA003's dialect options."""

from __future__ import annotations

from pathlib import Path

import pytest

from usdrender_lint.config import ConfigError, read_config_file
from usdrender_lint.registry import build_registry
from usdrender_lint.rules._lpe import lpe_problem, parse_lpe, strip_renderer_prefix
from usdrender_lint.rules.vars.va003_lpe_malformed import LpeMalformed
from usdrender_lint.running.pipeline import make_rules
from usdrender_lint.testing import lint_text

VALID = [
    "C<RD>[<L.>O]",  # RenderVar.md's canonical example
    "C.*",
    "C.*<L.'key'>",
    "CD*L",
    "C<R[DG]>+L",
    "C(<RD>|<RG>){1,3}L",
    "C[^DS]{2,}O",
    "C<TS>*<RD>'rim'L",
    "(C|L).*",
    ".*L",
    "<C..>.*<L..>",
    "<C.x>B",
    "C()L",
]


@pytest.mark.parametrize("expression", VALID)
def test_valid_expressions_parse(expression: str) -> None:
    assert lpe_problem(expression) is None


# (expression, what the message says, 0-based position it points at)
MALFORMED = [
    ("C<RD>[<L.>O", "unbalanced '['", 5),
    ("C(RD", "unbalanced '('", 1),
    ("C<RD", "unbalanced '<'", 1),
    ("CD)L", "unbalanced ')'", 2),
    ("CL]", "unbalanced ']'", 2),
    ("C.>", "unbalanced '>'", 2),
    ("C'rim", "unbalanced quote", 1),
    ("|CL", "no left operand", 0),
    ("CD|", "no right operand", 2),
    ("C<<L.>>", "cannot be nested", 2),
    ("C<R*>L", "repetition '*' is not allowed inside", 3),
    ("C<R{2}>L", "repetition '{' is not allowed inside", 3),
    ("CD{2,1}L", "m is less than n", 2),
    ("CD{,2}L", "malformed repetition", 2),
    ("CD{2L", "malformed repetition", 2),
    ("C[^]L", "'[^]' is empty", 1),
    ("CQL", "unknown label 'Q'", 1),
    ("C<DR>L", "position 1 of '<...>' must be an event type", 2),
    ("C<RR>L", "position 2 of '<...>' must be a scattering type", 3),
    ("C<R[DL]>L", "position 2 of '<...>' must be a scattering type", 5),
    ("CD?L", "'?' is not OSL LPE syntax", 2),
    ("C*+L", "'+' has nothing to repeat", 2),
    ("LD*C", "must begin with the camera event C", 0),
    ("[^C].*", "must begin with the camera event C", 0),
    ("", "empty", 0),
]


@pytest.mark.parametrize(("expression", "message", "position"), MALFORMED)
def test_malformed_expressions_are_explained(expression: str, message: str, position: int):
    problem = lpe_problem(expression)
    assert problem is not None, expression
    assert message in problem.message
    assert problem.position == position
    assert f"at character {position + 1}" in str(problem)


def test_optional_camera_prefix_still_reaches_c() -> None:
    # D* may match nothing, so the path can still start at C.
    assert lpe_problem("D*CL") is None
    assert lpe_problem("DCL") is not None


def test_extended_dialect_admits_renderer_extensions() -> None:
    assert lpe_problem("CD?L", "extended") is None
    assert lpe_problem("C<RU>L", "extended") is None
    # Structure is still checked in the extended dialect.
    assert "unbalanced" in lpe_problem("C<RD>[<L.>O", "extended").message


def test_extra_labels_admit_named_labels_only() -> None:
    assert lpe_problem("CUL", extra_labels=("U",)) is None
    assert "unknown label 'W'" in lpe_problem("CWL", extra_labels=("U",)).message


def test_a_remembered_answer_is_kept_apart_per_dialect_and_labels(monkeypatch) -> None:
    from usdrender_lint.rules import _lpe

    parsed: list[str] = []
    parse = _lpe.parse_lpe

    def counting(text, *args):
        parsed.append(text)
        return parse(text, *args)

    monkeypatch.setattr(_lpe, "parse_lpe", counting)
    _lpe._lpe_problem.cache_clear()
    assert lpe_problem("CQL") is not None
    assert lpe_problem("CQL") is not None
    assert parsed == ["CQL"]  # the second answer is remembered
    assert lpe_problem("CQL", extra_labels=["Q"]) is None  # any iterable of labels
    assert lpe_problem("CD?L", "extended") is None
    assert lpe_problem("CD?L") is not None
    assert parsed == ["CQL", "CQL", "CD?L", "CD?L"]


def test_parse_tree_shape() -> None:
    tree = parse_lpe("C<RD>*L")
    assert tree.kind == "cat"
    assert [c.kind for c in tree.children] == ["label", "event", "label"]
    event = tree.children[1]
    assert (event.min_repeat, event.max_repeat) == (0, -1)
    assert [c.text for c in event.children] == ["R", "D"]


def test_strip_renderer_prefix() -> None:
    assert strip_renderer_prefix("lpe:C.*") == ("C.*", True)
    assert strip_renderer_prefix("C.*") == ("C.*", False)
    assert strip_renderer_prefix("lpe:lpe:C") == ("lpe:C", True)


# -- VA003 options -----------------------------------------------------------------

OPTIONAL_LPE = """#usda 1.0

def Scope "Render"
{
    def Scope "Vars"
    {
        def RenderVar "optional"
        {
            string sourceName = "lpe:CD?L"
            uniform token sourceType = "lpe"
        }
    }
}
"""


def _va003(rule: LpeMalformed) -> list[str]:
    return [f.message for f in lint_text(OPTIONAL_LPE, rules=[rule]) if f.code == "VA003"]


def test_dialect_option_changes_the_verdict() -> None:
    strict = _va003(LpeMalformed())
    assert len(strict) == 1
    assert "'?' is not OSL LPE syntax" in strict[0]
    assert "(at character 7)" in strict[0]
    assert "'lpe:'" in strict[0]
    extended = _va003(LpeMalformed(LpeMalformed.Options(dialect="extended")))
    # Only the non-portable prefix remains.
    assert len(extended) == 1
    assert "malformed" not in extended[0] and "'lpe:'" in extended[0]


def _rules_from_config(tmp_path: Path, toml: str):
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text(toml, encoding="utf-8")
    return make_rules(build_registry(), read_config_file(config))


def test_dialect_option_from_config(tmp_path: Path) -> None:
    rules = _rules_from_config(
        tmp_path, '[rules.lpe-malformed]\ndialect = "extended"\nextra-labels = ["U"]\n'
    )
    (rule,) = [r for r in rules if r.code == "VA003"]
    assert rule.options == LpeMalformed.Options(dialect="extended", extra_labels=("U",))


@pytest.mark.parametrize(
    "table",
    [
        '[rules.VA003]\ndialect = "renderman"\n',  # not an allowed value
        "[rules.VA003]\ndialect = 1\n",  # wrong type
        '[rules.VA003]\nextra-labels = "U"\n',  # not a list
        "[rules.VA003]\nstrict = true\n",  # unknown option
    ],
)
def test_bad_dialect_options_are_config_errors(tmp_path: Path, table: str) -> None:
    with pytest.raises(ConfigError, match="VA003"):
        _rules_from_config(tmp_path, table)


def test_hostile_expressions_are_reported_not_crashed() -> None:
    deep = "C" + "(" * 5000 + "L" + ")" * 5000
    assert "nested more than" in lpe_problem(deep).message
    assert lpe_problem("C" + "(" * 50 + "L" + ")" * 50) is None
    wide = "C(" + "|".join(["L"] * 5000) + ")"
    assert lpe_problem(wide) is None
    assert len(parse_lpe(wide).children[1].children[0].children) == 5000
