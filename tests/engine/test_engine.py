"""The engine: dispatch, isolation, locations, diagnostics capture."""

from __future__ import annotations

from pathlib import Path

import pytest
from pxr import Sdf, Usd, UsdRender

from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity
from usdrender_lint.engine import Linter
from usdrender_lint.layers.usda_text import index_usda
from usdrender_lint.model import INTERNAL_ERROR_CODE

SHOT = """#usda 1.0
(
    subLayers = [@./weak.usda@]
)

def Scope "Render"
{
    def RenderSettings "Settings"
    {
        rel products = </Render/Beauty>
    }

    def RenderProduct "Beauty"
    {
    }
}
"""

WEAK = """#usda 1.0

over "Render"
{
    over "Settings"
    {

        uniform int2 resolution = (-1, 1080)
    }
}
"""


@pytest.fixture
def shot(tmp_path: Path) -> Path:
    (tmp_path / "weak.usda").write_text(WEAK)
    path = tmp_path / "shot.usda"
    path.write_text(SHOT)
    return path


class Recorder(Rule):
    """Records which prims it is handed.

    ## What it does
    Test rule.
    """

    code = "TST001"
    name = "recorder"
    severity = Severity.INFO
    prim_types = (UsdRender.Product,)

    def __init__(self, options=None) -> None:
        super().__init__(options)
        self.seen: list[str] = []

    def check_prim(self, prim, ctx):
        self.seen.append(str(prim.GetPath()))
        return ()


class Exploder(Rule):
    """Raises.

    ## What it does
    Test rule.
    """

    code = "TST002"
    name = "exploder"
    severity = Severity.ERROR
    prim_types = (UsdRender.SettingsBase,)

    def check_prim(self, prim, ctx):
        raise ValueError("boom")


class ResolutionReporter(Rule):
    """Reports the resolution attribute wherever it is.

    ## What it does
    Test rule.
    """

    code = "TST003"
    name = "resolution-reporter"
    severity = Severity.WARNING
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim, ctx):
        yield Diagnostic(message="resolution", at=prim.GetAttribute("resolution"))
        # The same diagnostic twice is reported once.
        yield Diagnostic(message="resolution", at=prim.GetAttribute("resolution"))


def test_prims_are_dispatched_by_schema_type(shot: Path) -> None:
    recorder = Recorder()
    Linter([recorder]).lint_path(str(shot))
    assert recorder.seen == ["/Render/Beauty"]


def test_a_raising_rule_is_isolated(shot: Path) -> None:
    result = Linter([Exploder(), ResolutionReporter()]).lint_path(str(shot))
    codes = [f.code for f in result.findings]
    assert codes.count(INTERNAL_ERROR_CODE) == 2  # the settings and the product
    assert "TST003" in codes
    internal = next(f for f in result.findings if f.code == INTERNAL_ERROR_CODE)
    assert "TST002 (exploder) raised ValueError: boom" in internal.message
    # Not a rule of usdrender-lint's own: its report goes to its package's authors.
    assert internal.message.endswith(
        f"Please report this to the authors of {__name__.partition('.')[0]}."
    )
    assert internal.severity is Severity.ERROR


class Malformed(Rule):
    """Yields what it was handed in ``bad``.

    ## What it does
    Test rule.
    """

    code = "TST009"
    name = "malformed"
    severity = Severity.WARNING
    prim_types = (UsdRender.Settings,)

    def __init__(self, bad) -> None:
        super().__init__()
        self.bad = bad

    def check_prim(self, prim, ctx):
        yield self.bad(prim)


@pytest.mark.parametrize(
    ("bad", "said"),
    [
        (lambda prim: "text", "yielded str 'text', not a Diagnostic"),
        (lambda prim: Diagnostic(message=None, at=prim), "message is NoneType, not a str"),
        (lambda prim: Diagnostic(message="m", at="/Render"), "at is str, not a USD object"),
        (lambda prim: Diagnostic(message="m", at=prim, fix="x"), "fix is str, not a Fix"),
        # A Fix without apply was listed as "fixable with --fix", which then did nothing.
        (
            lambda prim: Diagnostic(message="m", at=prim, fix=Fix(description="d", safe=True)),
            "yielded a Fix whose apply is NoneType, not a callable apply(stage)",
        ),
        (
            lambda prim: Diagnostic(
                message="m", at=prim, fix=Fix(description="d", safe="yes", apply=print)
            ),
            "yielded a Fix whose safe is str, not a bool",
        ),
    ],
)
def test_a_malformed_diagnostic_is_said_to_be_the_rules(shot: Path, bad, said: str) -> None:
    # The engine's own line ([linter.py:589]) and "'str' object has no attribute
    # 'at'" sent the plugin's author to report a bug in usdrender-lint.
    result = Linter([Malformed(bad), ResolutionReporter()]).lint_path(str(shot))
    (internal,) = [f for f in result.findings if f.code == INTERNAL_ERROR_CODE]
    assert internal.message.startswith("rule TST009 (malformed) yielded ")
    assert said in internal.message
    assert "Please report this to the authors of " in internal.message
    assert "TST003" in [f.code for f in result.findings]


class Returner(Rule):
    """Returns a Diagnostic instead of yielding it.

    ## What it does
    Test rule.
    """

    code = "TST011"
    name = "returner"
    severity = Severity.WARNING
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim, ctx):
        return Diagnostic(message="returned", at=prim)


def test_a_hook_that_returns_a_diagnostic_is_said_to_be_the_rules(shot: Path) -> None:
    result = Linter([Returner(), ResolutionReporter()]).lint_path(str(shot))
    (internal,) = [f for f in result.findings if f.code == INTERNAL_ERROR_CODE]
    assert internal.message.startswith(
        "rule TST011 (returner) returned Diagnostic Diagnostic(message='returned'"
    )
    assert "not an iterable of Diagnostics" in internal.message
    assert "Please report this to the authors of " in internal.message
    assert "TST003" in [f.code for f in result.findings]


class Exiter(Rule):
    """Calls sys.exit.

    ## What it does
    Test rule.
    """

    code = "TST012"
    name = "exiter"
    severity = Severity.WARNING
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim, ctx):
        raise SystemExit(3)


def test_a_rule_that_calls_sys_exit_is_isolated(shot: Path) -> None:
    # A lone file is linted in the command's process: its sys.exit(3) ended the
    # run with status 3, no report and no message.
    result = Linter([Exiter(), ResolutionReporter()]).lint_path(str(shot))
    (internal,) = [f for f in result.findings if f.code == INTERNAL_ERROR_CODE]
    assert "rule TST012 (exiter) raised SystemExit: 3" in internal.message
    assert "TST003" in [f.code for f in result.findings]


class Mutator(Rule):
    """Edits the stage it lints.

    ## What it does
    Test rule.
    """

    code = "TST010"
    name = "mutator"
    severity = Severity.WARNING
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim, ctx):
        prim.SetCustomDataByKey("edited", True)
        yield Diagnostic(message="edited", at=prim)


def test_a_rule_cannot_edit_the_stage_it_lints(shot: Path) -> None:
    # lint_stage lints the caller's stage, and --fix and a ValidationFixer save the
    # layer: a hook's edit would reach the user's file.
    stage = Usd.Stage.Open(str(shot))
    findings = Linter([Mutator(), ResolutionReporter()]).lint_stage(stage, str(shot))
    (internal,) = [f for f in findings if f.code == INTERNAL_ERROR_CODE]
    assert "TST010 (mutator) raised" in internal.message
    assert "is not editable" in internal.message
    assert stage.GetPrimAtPath("/Render/Settings").GetCustomDataByKey("edited") is None
    assert not any(layer.dirty for layer in stage.GetUsedLayers())
    # The layers are editable again afterwards.
    assert all(layer.permissionToEdit for layer in stage.GetUsedLayers())
    assert "TST003" in [f.code for f in findings]


def test_raise_errors_propagates_for_tests(shot: Path) -> None:
    with pytest.raises(ValueError):
        Linter([Exploder()], raise_errors=True).lint_path(str(shot))


def test_only_rules_with_their_own_check_stage_are_called_per_stage(
    shot: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls: list[str] = []

    def base_check_stage(self, ctx):  # stands in for the base hook, which yields nothing
        calls.append(self.code)
        return ()

    monkeypatch.setattr(Rule, "check_stage", base_check_stage)
    staged = Recorder()
    staged.check_stage = lambda ctx: calls.append("instance") or ()  # set on the instance
    Linter([Recorder(), ResolutionReporter(), staged]).lint_path(str(shot))
    assert calls == ["instance"]


def test_finding_names_the_layer_and_line_of_the_strongest_opinion(shot: Path) -> None:
    (finding,) = Linter([ResolutionReporter()]).lint_path(str(shot)).findings
    assert finding.location.path == "/Render/Settings.resolution"
    assert finding.location.file == str(shot)
    assert finding.location.layer == str(shot.parent / "weak.usda")
    assert finding.location.line == 8


def test_severity_override(shot: Path) -> None:
    (finding,) = (
        Linter([ResolutionReporter()], {"TST003": Severity.ERROR}).lint_path(str(shot)).findings
    )
    assert finding.severity is Severity.ERROR


def test_usdc_layers_have_no_line(shot: Path, tmp_path: Path) -> None:
    stage = Usd.Stage.Open(str(shot))
    flat = tmp_path / "flat.usdc"
    stage.Export(str(flat))
    (finding,) = Linter([ResolutionReporter()]).lint_path(str(flat)).findings
    assert finding.location.layer == str(flat)
    assert finding.location.line is None


def test_usd_diagnostics_are_trapped(tmp_path: Path, capfd) -> None:
    layer = tmp_path / "a.usda"
    layer.write_text("#usda 1.0\n(\n    subLayers = [@./missing.usda@]\n)\n")
    result = Linter([ResolutionReporter()]).lint_path(str(layer))
    assert result.status == "linted"
    captured = capfd.readouterr()
    assert captured.err == "" and captured.out == ""


def test_directory_and_missing_paths_are_file_errors(tmp_path: Path) -> None:
    linter = Linter([])
    assert linter.lint_path(str(tmp_path)).status == "error"
    missing = linter.lint_path(str(tmp_path / "none.usda"))
    assert missing.status == "error" and "no such file" in missing.error


def test_open_failure_is_st001_with_line(tmp_path: Path) -> None:
    layer = tmp_path / "bad.usda"
    layer.write_text('#usda 1.0\ndef Scope "A"\n{\n    int x = \n}\n')
    (finding,) = Linter([]).lint_path(str(layer)).findings
    assert finding.code == "ST001"
    assert (finding.location.layer, finding.location.line) == (str(layer), 4)
    # The location says where; the message does not repeat the absolute path.
    assert str(layer) not in finding.message
    assert finding.message == "Expected } at 'int x = ' in </A>"


def test_open_failure_names_no_usd_internal_namespace(tmp_path: Path) -> None:
    layer = tmp_path / "bad.usda"
    layer.write_text("#usda 1.0\ndef 5\n")
    (finding,) = Linter([]).lint_path(str(layer)).findings
    # Not "parse error matching pxrInternal_v0_26_11__pxrReserved___pegtl::internal::eof".
    assert finding.message == "Expected end of file at 'def 5' in </>"


def test_line_index_handles_variants_strings_and_nesting() -> None:
    text = '''#usda 1.0
(
    customLayerData = { string note = "def Scope \\"Fake\\" {" }
)
# def Xform "Commented"
def Xform "World" (
    variants = { string look = "a" }
    prepend variantSets = "look"
)
{
    variantSet "look" = {
        "a" {
            def Camera "cam"
            {
                float focalLength.timeSamples = {
                    1: 35,
                }
            }
        }
    }
    custom string notes = """two
lines"""
    rel target = </World>
}
'''
    index = index_usda(text)
    assert index["/World"] == 6
    assert index["/World{look=a}cam"] == 13
    assert index["/World{look=a}cam.focalLength"] == 15
    assert index["/World.notes"] == 21
    assert index["/World.target"] == 23
    assert not any("Fake" in key or "Commented" in key for key in index)


def test_context_cached_computes_each_call_once_none_included() -> None:
    stage = Usd.Stage.CreateInMemory()
    prim = stage.DefinePrim("/Render/Settings", "RenderSettings")
    ctx = Context(stage=stage, file="shot.usda")
    calls: list[tuple[str, object]] = []

    def nothing(ctx: Context, prim: Usd.Prim) -> None:
        calls.append(("nothing", prim))
        return None

    def name_of(ctx: Context, prim: Usd.Prim, suffix: str) -> str:
        calls.append(("name_of", suffix))
        return prim.GetName() + suffix

    assert ctx.cached(nothing, prim) is None
    assert ctx.cached(nothing, prim) is None  # None is a remembered answer
    assert ctx.cached(name_of, prim, "!") == "Settings!"
    assert ctx.cached(name_of, prim, "!") == "Settings!"
    assert ctx.cached(name_of, prim, "?") == "Settings?"  # other arguments, other answer
    assert calls == [("nothing", prim), ("name_of", "!"), ("name_of", "?")]
    # Keyed by function: another function with the same arguments is computed anew.
    assert ctx.cached(lambda ctx, prim: "other", prim) == "other"


def test_the_cache_is_dropped_with_the_lint() -> None:
    stage = Usd.Stage.CreateInMemory()
    stage.DefinePrim("/Render/Settings", "RenderSettings")
    caches: list[object] = []

    class Probe(Rule):
        """Records the lint's cache (test-only).

        ## What it does
        ## Why is this bad?
        ## Example
        ## Use instead
        ## Fix safety
        """

        code = "ZZ960"
        name = "cache-probe"
        severity = Severity.INFO
        prim_types = (UsdRender.Settings,)

        def check_prim(self, prim, ctx):
            caches.append(ctx.cache)
            ctx.cached(lambda ctx: 1)
            yield from ()

    linter = Linter([Probe()], raise_errors=True)
    linter.lint_stage(stage)
    linter.lint_stage(stage)
    assert len(caches) == 2 and caches[0] is not caches[1]
    assert all(len(cache) >= 1 for cache in caches)


class HalfwayExploder(Rule):
    """Reports a prim, then raises.

    ## What it does
    Test rule.
    """

    code = "TST004"
    name = "halfway-exploder"
    severity = Severity.ERROR
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim, ctx):
        yield Diagnostic(message="before the error", at=prim)
        raise ValueError("boom")


def test_a_rule_raising_part_way_loses_its_findings_on_that_prim_only(shot: Path) -> None:
    run = Linter([HalfwayExploder(), ResolutionReporter()]).run_path(str(shot))
    codes = [f.code for f in run.findings]
    assert codes.count(INTERNAL_ERROR_CODE) == 1 and "TST004" not in codes
    assert "TST003" in codes  # the next rule on the same prim still ran
    internal = next(f for f in run.findings if f.code == INTERNAL_ERROR_CODE)
    assert run.origin(internal) == ("TST004", Sdf.Path("/Render/Settings"))
    reported = next(f for f in run.findings if f.code == "TST003")
    assert run.origin(reported) == ("TST003", Sdf.Path("/Render/Settings"))
