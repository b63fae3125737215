"""customData suppressions (engine) and per-path-ignores (after linting)."""

from __future__ import annotations

from pathlib import Path

import pytest
from pxr import UsdRender

from usdrender_lint.api import Rule
from usdrender_lint.engine import Linter, suppress
from usdrender_lint.model import FileResult, Finding, Location, Report, Severity
from usdrender_lint.registry import build_registry
from usdrender_lint.running.path_ignores import apply_path_ignores
from usdrender_lint.testing import lint_text

REGISTRY = build_registry()

BAD_WINDOW = """#usda 1.0

def Scope "Render"
{{
    def RenderSettings "Settings" (
        {metadata}
    )
    {{
        uniform float4 dataWindowNDC = (0.8, 0, 0.2, 1)
    }}

    def RenderSettings "Other"
    {{
        uniform float4 dataWindowNDC = (0.8, 0, 0.2, 1)
    }}
}}
"""


def _ignore(*entries: str) -> str:
    listed = ", ".join(f'"{e}"' for e in entries)
    return f"customData = {{ dictionary usdrender_lint = {{ string[] ignore = [{listed}] }} }}"


def _lint(text: str, codes: tuple[str, ...] | None = None) -> list[Finding]:
    return lint_text(text, select=codes, name="shot.usda")


def _pairs(findings: list[Finding]) -> set[tuple[str, str | None]]:
    return {(f.code, f.location.path) for f in findings}


@pytest.mark.parametrize("entry", ["SE003", "se003", "data-window-malformed"])
def test_entry_silences_the_rule_on_the_prim_and_its_properties(entry) -> None:
    found = _pairs(_lint(BAD_WINDOW.format(metadata=_ignore(entry))))
    assert ("SE003", "/Render/Settings.dataWindowNDC") not in found
    # Only that prim: the sibling keeps its finding, and the entry was used.
    assert ("SE003", "/Render/Other.dataWindowNDC") in found
    assert not any(code == "UL001" for code, _ in found)


def test_without_suppression_both_prims_report() -> None:
    found = _pairs(_lint(BAD_WINDOW.format(metadata="")))
    assert ("SE003", "/Render/Settings.dataWindowNDC") in found
    assert ("SE003", "/Render/Other.dataWindowNDC") in found


def test_suppression_does_not_reach_children() -> None:
    text = f"""#usda 1.0

def Scope "Render" (
    {_ignore("SE003")}
)
{{
    def RenderSettings "Settings"
    {{
        uniform float4 dataWindowNDC = (0.8, 0, 0.2, 1)
    }}
}}
"""
    found = _pairs(_lint(text))
    assert ("SE003", "/Render/Settings.dataWindowNDC") in found
    assert ("UL001", "/Render") in found


def test_unused_entry_for_an_unselected_rule_is_not_reported() -> None:
    text = BAD_WINDOW.format(metadata=_ignore("SE003", "CA004"))
    found = _pairs(_lint(text, codes=("SE003", "UL001")))
    assert found == {("SE003", "/Render/Other.dataWindowNDC")}


def test_unused_entries_are_info_with_the_reason() -> None:
    text = BAD_WINDOW.format(metadata=_ignore("SE003", "SE007", "XX999"))
    unused = [f for f in _lint(text) if f.code == "UL001"]
    assert [f.severity for f in unused] == [Severity.INFO, Severity.INFO]
    messages = sorted(f.message for f in unused)
    assert "SE007 reports nothing on this prim" in messages[0]
    assert "'XX999'" in messages[1] and "no rule has this code or name" in messages[1]
    assert all(f.location.line == 5 for f in unused)  # the prim's line


def test_no_prim_is_asked_for_suppressions_when_no_layer_can_hold_one(monkeypatch) -> None:
    def never(*args, **kwargs):
        raise AssertionError("asked for suppressions where no layer holds the key")

    monkeypatch.setattr(suppress, "apply_data_suppressions", never)
    found = _pairs(_lint(BAD_WINDOW.format(metadata="")))
    assert ("SE003", "/Render/Settings.dataWindowNDC") in found


def test_the_engine_hands_over_the_suppressing_prims_of_its_walk(monkeypatch) -> None:
    text = BAD_WINDOW.format(metadata=_ignore("SE003", "SE007", "XX999")).replace(
        'RenderSettings "Other"', f'RenderSettings "Other" ({_ignore("nothing")})'
    )
    handed = []
    original = suppress.apply_data_suppressions

    def recording(stage, findings, rules, known_rules=None, *, suppressing=None, failed=()):
        handed.append([str(prim.GetPath()) for prim in suppressing])
        findings = list(findings)
        kept, unused = original(
            stage, findings, rules, known_rules, suppressing=suppressing, failed=failed
        )
        traversed = original(stage, findings, rules, known_rules)
        assert (kept, [(d.message, d.at) for d in unused]) == (
            traversed[0],
            [(d.message, d.at) for d in traversed[1]],
        )
        return kept, unused

    monkeypatch.setattr(suppress, "apply_data_suppressions", recording)
    unused = [f for f in _lint(text) if f.code == "UL001"]
    assert handed == [["/Render/Settings", "/Render/Other"]]
    assert len(unused) == 3


def test_without_the_meta_rule_unused_entries_are_silent() -> None:
    text = BAD_WINDOW.format(metadata=_ignore("SE003", "XX999"))
    found = _pairs(_lint(text, codes=("SE003",)))
    assert found == {("SE003", "/Render/Other.dataWindowNDC")}


# -- per-path-ignores -------------------------------------------------------------


def _report(*findings: Finding) -> Report:
    return Report((FileResult("f", findings=findings),))


def _finding(code: str, file: str, layer: str | None = None) -> Finding:
    rule = REGISTRY.find(code)
    name = rule.name if rule else "internal-error"
    return Finding(code, name, Severity.ERROR, "m", Location(file, "/Render/S", layer))


@pytest.mark.parametrize(
    ("pattern", "selectors", "ignored"),
    [
        ("shots/*.usda", ["SE003"], True),
        ("shots/*.usda", ["SE"], True),
        ("shots/*.usda", ["data-window-malformed"], True),
        ("shots/*.usda", ["ALL"], True),
        ("shots/*.usda", ["SE007"], False),
        ("*.usda", ["SE003"], True),  # no "/": the file name in any folder
        ("**/a.usda", ["SE003"], True),  # "**/" also matches no folder
        ("other/*.usda", ["SE003"], False),
        ("lib/*.usda", ["SE003"], True),  # the layer holding the opinion matches
    ],
)
def test_per_path_ignores(tmp_path, pattern, selectors, ignored) -> None:
    finding = _finding("SE003", str(tmp_path / "shots" / "a.usda"), str(tmp_path / "lib/x.usda"))
    result = apply_path_ignores(_report(finding), {pattern: selectors}, tmp_path, REGISTRY.rules)
    assert (not result.findings) is ignored


def test_internal_errors_are_never_path_ignored(tmp_path) -> None:
    finding = _finding("UL000", str(tmp_path / "a.usda"))
    result = apply_path_ignores(_report(finding), {"*": ["ALL"]}, tmp_path, REGISTRY.rules)
    assert result.findings == (finding,)


def test_the_guides_suppression_example_works() -> None:
    from usdrender_lint.api.docs import code_blocks

    guide = Path(__file__).parents[2] / "docs" / "guides" / "configuration.md"
    section = guide.read_text(encoding="utf-8").split("## Suppressing findings", 1)[1]
    section = section.split("\n## ", 1)[0]
    (example,) = code_blocks(section)
    silenced = _pairs(_lint(example))
    assert not {code for code, _ in silenced} & {"SE003", "CA001", "UL001"}
    unsuppressed = example.replace("usdrender_lint", "pipeline")
    assert {"SE003", "CA001"} <= {code for code, _ in _pairs(_lint(unsuppressed))}


# -- the UL001 fix ----------------------------------------------------------------

STALE = """#usda 1.0
(
    subLayers = [@./weak.usda@]
)

def Scope "Render"
{
    def RenderSettings "Settings" (
        customData = {
            int keep = 1
            dictionary usdrender_lint = {
                string[] ignore = ["SE003", "SE007", "XX999"]
            }
        }
    )
    {
        uniform float4 dataWindowNDC = (0.8, 0, 0.2, 1)
    }
}
"""


def _fix_all(path: Path, monkeypatch) -> tuple[list[list[str]], object]:
    """Lint, then apply every UL001 fix the way the fixer does (edit target =
    the fix's layer); return the ignore lists left, strongest first."""
    from pxr import Usd

    from usdrender_lint import engine

    produced = []
    original = suppress.apply_data_suppressions

    def recording(*args, **kwargs):
        kept, unused = original(*args, **kwargs)
        produced.extend(unused)
        return kept, unused

    monkeypatch.setattr(engine.suppress, "apply_data_suppressions", recording)
    stage = Usd.Stage.Open(str(path))
    Linter([r() for r in REGISTRY.rules], raise_errors=True).lint_stage(stage, str(path))
    monkeypatch.undo()
    assert produced and all(d.fix is not None and d.fix.safe for d in produced)
    for diagnostic in produced:
        stage.SetEditTarget(Usd.EditTarget(diagnostic.fix.layer))
        diagnostic.fix.apply(stage)
    lists = [
        list(spec.customData.get("usdrender_lint", {}).get("ignore", ["<cleared>"]))
        for spec in stage.GetPrimAtPath("/Render/Settings").GetPrimStack()
    ]
    return lists, stage


def test_fix_removes_only_the_unused_entries(tmp_path, monkeypatch) -> None:
    (tmp_path / "weak.usda").write_text("#usda 1.0\n", encoding="utf-8")
    (tmp_path / "shot.usda").write_text(STALE, encoding="utf-8")
    lists, stage = _fix_all(tmp_path / "shot.usda", monkeypatch)
    assert lists == [["SE003"]]
    assert stage.GetPrimAtPath("/Render/Settings").GetCustomDataByKey("keep") == 1
    stage.GetRootLayer().Save()
    found = Linter([r() for r in REGISTRY.rules]).lint_path(str(tmp_path / "shot.usda")).findings
    assert not {f.code for f in found} & {"UL001", "SE003"}


def test_fix_clears_an_emptied_list_unless_a_weaker_layer_has_one(tmp_path, monkeypatch) -> None:
    stale_only = STALE.replace('"SE003", ', "")
    (tmp_path / "shot.usda").write_text(stale_only, encoding="utf-8")
    (tmp_path / "weak.usda").write_text("#usda 1.0\n", encoding="utf-8")
    lists, _ = _fix_all(tmp_path / "shot.usda", monkeypatch)
    assert lists == [["<cleared>"]]

    weak = (
        STALE.split(")\n", 1)[1].replace("def Scope", "over").replace("def RenderSettings", "over")
    )
    # A fresh folder: the first stage's edited layers stay open in Sdf's registry.
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "shot.usda").write_text(stale_only, encoding="utf-8")
    (tmp_path / "b" / "weak.usda").write_text("#usda 1.0\n" + weak, encoding="utf-8")
    lists, stage = _fix_all(tmp_path / "b" / "shot.usda", monkeypatch)
    # The empty list keeps hiding the weaker layer's list.
    assert lists == [[], ["SE003", "SE007", "XX999"]]
    assert (
        list(stage.GetPrimAtPath("/Render/Settings").GetCustomDataByKey("usdrender_lint:ignore"))
        == []
    )


class _RaisesOnSettings(Rule):
    """Raises on every RenderSettings.

    ## What it does
    Test rule.
    """

    code = "TST021"
    name = "raises-on-settings"
    severity = Severity.WARNING
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim, ctx):
        raise RuntimeError("boom")


def test_a_suppression_of_a_rule_that_raised_is_not_called_unused(tmp_path: Path) -> None:
    # Its findings are lost, so whether the entry silences one is unknown: calling it
    # unused would offer a safe --fix that deletes it.
    path = tmp_path / "shot.usda"
    path.write_text(BAD_WINDOW.format(metadata=_ignore("TST021", "SE003")))
    rules = [_RaisesOnSettings(), REGISTRY.by_code("SE003")(), REGISTRY.by_code("UL001")()]
    findings = Linter(rules).lint_path(str(path)).findings
    assert [f.code for f in findings if f.location.path == "/Render/Settings"] == ["UL000"]
    assert not any(f.code == "UL001" for f in findings)
