"""Third-party rules plug in through the same entry point group as the built-ins.

Each test writes a tiny distribution (a module plus its ``.dist-info`` entry
point metadata) into a temporary folder on ``sys.path``: importlib.metadata then
discovers it exactly as it would an installed package.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint.cli import cli
from usdrender_lint.registry import RegistryError, build_registry

ACME_RULES = '''
from pxr import UsdRender
from usdrender_lint.api import Diagnostic, Rule, Severity


class ProductNameHasFrameToken(Rule):
    """Studio rule: every productName carries a frame token.

    ## What it does
    Reports a RenderProduct whose productName has no `####`.
    """

    code = "ACME001"
    name = "product-name-frame-token"
    severity = Severity.WARNING
    prim_types = (UsdRender.Product,)

    def check_prim(self, prim, ctx):
        name = UsdRender.Product(prim).GetProductNameAttr().Get() or ""
        if "####" not in name:
            yield Diagnostic(message=f"productName {name!r} has no frame token ####", at=prim)


RULES = [ProductNameHasFrameToken]
'''

LAYER = """#usda 1.0

def Scope "Render"
{
    def RenderProduct "beauty"
    {
        token productName = "beauty.exr"
        rel orderedVars = </Render/color>
    }

    def RenderVar "color"
    {
        string sourceName = "Ci"
    }
}
"""


def install_plugin(
    root: Path, dist: str, module: str, source: str, value: str, entry: str | None = None
) -> None:
    """``entry``: the entry point's name (default: the distribution's)."""
    (root / f"{module}.py").write_text(textwrap.dedent(source))
    info = root / f"{dist}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(f"[usdrender_lint.rules]\n{entry or dist} = {value}\n")


@pytest.fixture
def layer(tmp_path: Path) -> Path:
    path = tmp_path / "shot.usda"
    path.write_text(LAYER)
    return path


def test_third_party_rule_runs(tmp_path: Path, layer: Path, monkeypatch) -> None:
    site = tmp_path / "site"
    site.mkdir()
    install_plugin(site, "acme", "acme_rules", ACME_RULES, "acme_rules:RULES")
    monkeypatch.syspath_prepend(str(site))

    registry = build_registry()
    assert registry.origins["ACME001"] == "acme"
    result = CliRunner().invoke(cli, ["check", "--isolated", "--format", "json", str(layer)])
    codes = {f["code"] for f in json.loads(result.output)["files"][0]["findings"]}
    assert "ACME001" in codes
    listed = json.loads(CliRunner().invoke(cli, ["rules", "--format", "json"]).output)
    assert {"code": "ACME001", "plugin": "acme"}.items() <= next(
        r for r in listed if r["code"] == "ACME001"
    ).items()


def test_plugin_that_fails_to_import_stops_the_run(
    tmp_path: Path, layer: Path, monkeypatch
) -> None:
    site = tmp_path / "site"
    site.mkdir()
    install_plugin(
        site, "broken", "broken_rules", "import not_a_module_anywhere\n", "broken_rules:RULES"
    )
    monkeypatch.syspath_prepend(str(site))
    result = CliRunner().invoke(cli, ["check", "--isolated", str(layer)])
    assert result.exit_code == 2
    assert "rule plugin 'broken'" in result.stderr
    assert "failed to load" in result.stderr
    assert "Traceback" not in result.output


def test_a_rule_without_a_docstring_is_refused_naming_its_plugin_and_class(
    tmp_path: Path, layer: Path, monkeypatch
) -> None:
    """Its docstring is its documentation: without one, rules listed an empty
    summary and explain printed only the rule's header, in silence."""
    site = tmp_path / "site"
    site.mkdir()
    start = ACME_RULES.index('    """Studio rule')
    bare = ACME_RULES[:start] + ACME_RULES[ACME_RULES.index('"""\n', start + 8) + 4 :]
    assert "Studio rule" not in bare
    install_plugin(site, "bare", "bare_rules", bare, "bare_rules:RULES")
    monkeypatch.syspath_prepend(str(site))
    for args in (["check", "--isolated", str(layer)], ["explain", "ACME001"], ["rules"]):
        result = CliRunner().invoke(cli, args)
        assert result.exit_code == 2, result.output
        assert result.stderr.count("\n") == 1, result.stderr
        assert "rule plugin 'bare' (bare_rules:RULES) failed to load: TypeError: rule class " in (
            result.stderr
        )
        assert "ProductNameHasFrameToken: no docstring" in result.stderr


def test_duplicate_code_stops_the_run(tmp_path: Path, layer: Path, monkeypatch) -> None:
    site = tmp_path / "site"
    site.mkdir()
    clash = ACME_RULES.replace('"ACME001"', '"CA004"').replace(
        "product-name-frame-token", "acme-clash"
    )
    install_plugin(site, "clash", "clash_rules", clash, "clash_rules:RULES")
    monkeypatch.syspath_prepend(str(site))
    with pytest.raises(RegistryError, match="duplicate rule code CA004"):
        build_registry()
    result = CliRunner().invoke(cli, ["check", "--isolated", str(layer)])
    assert result.exit_code == 2
    assert "duplicate rule code CA004" in result.stderr


def test_duplicate_code_names_each_plugin_by_its_entry_point(tmp_path: Path, monkeypatch) -> None:
    # Two packages may name their entry point alike ("acme"): the error tells them apart.
    site = tmp_path / "site"
    site.mkdir()
    install_plugin(site, "acme_a", "acme_a_rules", ACME_RULES, "acme_a_rules:RULES", "acme")
    other = ACME_RULES.replace("product-name-frame-token", "acme-other-name")
    install_plugin(site, "acme_b", "acme_b_rules", other, "acme_b_rules:RULES", "acme")
    monkeypatch.syspath_prepend(str(site))
    with pytest.raises(RegistryError) as raised:
        build_registry()
    message = str(raised.value)
    assert message.startswith("duplicate rule code ACME001")
    assert "acme_a_rules:RULES" in message and "acme_b_rules:RULES" in message


def test_alias_that_is_another_rules_name_stops_the_run(
    tmp_path: Path, layer: Path, monkeypatch
) -> None:
    # An alias is a name to selectors, suppressions and explain: a clash would make
    # `explain product-missing-render-vars` show the plugin's rule.
    site = tmp_path / "site"
    site.mkdir()
    aliased = ACME_RULES.replace(
        "    prim_types = (UsdRender.Product,)",
        '    prim_types = (UsdRender.Product,)\n    aliases = ("product-missing-render-vars",)',
    )
    install_plugin(site, "alias", "alias_rules", aliased, "alias_rules:RULES")
    monkeypatch.syspath_prepend(str(site))
    with pytest.raises(RegistryError, match="duplicate rule name 'product-missing-render-vars'"):
        build_registry()
    result = CliRunner().invoke(cli, ["explain", "product-missing-render-vars"])
    assert result.exit_code == 2
    assert "PR004" in result.stderr and "ACME001" in result.stderr


def test_plugin_providing_a_non_rule_is_rejected(tmp_path: Path, monkeypatch) -> None:
    site = tmp_path / "site"
    site.mkdir()
    install_plugin(site, "odd", "odd_rules", "RULES = [object]\n", "odd_rules:RULES")
    monkeypatch.syspath_prepend(str(site))
    with pytest.raises(RegistryError, match="not a Rule subclass"):
        build_registry()


def test_rule_metadata_is_checked_at_class_creation() -> None:
    from usdrender_lint.api import Rule, Severity

    with pytest.raises(TypeError, match="kebab-case"):

        class BadName(Rule):
            code = "ACME002"
            name = "Bad_Name"
            severity = Severity.ERROR


@pytest.mark.parametrize("prim_types", [("RenderProduct",), "UsdRenderProduct", (int,)])
def test_prim_types_are_checked_at_class_creation(prim_types) -> None:
    # A string failed every run later with "internal error: TypeError: String passed
    # to Tf.Type.Find()", naming neither the rule nor the plugin.
    from usdrender_lint.api import Rule, Severity

    with pytest.raises(TypeError, match="rule class BadTypes: prim_types .* is not a tuple"):
        type(
            "BadTypes",
            (Rule,),
            {
                "code": "ACME003",
                "name": "bad-types",
                "severity": Severity.ERROR,
                "prim_types": prim_types,
            },
        )


PRINTING_RULES = ACME_RULES.replace(
    "    def check_prim(self, prim, ctx):\n",
    "    def check_prim(self, prim, ctx):\n        print('debugging {not json')\n",
)


@pytest.mark.parametrize("fmt", ["json", "sarif"])
def test_a_rule_that_prints_leaves_the_report_alone(
    tmp_path: Path, layer: Path, monkeypatch, fmt: str
) -> None:
    # One file with --jobs 1 is linted in this process (as a lone file is in the
    # supervised child): the rule's print must not land in the report on stdout.
    site = tmp_path / "site"
    site.mkdir()
    install_plugin(site, "noisy", "noisy_rules", PRINTING_RULES, "noisy_rules:RULES")
    monkeypatch.syspath_prepend(str(site))
    args = ["check", "--isolated", "--no-cache", "--jobs", "1", "--timeout", "0"]
    result = CliRunner().invoke(cli, [*args, "--format", fmt, str(layer)])
    report = json.loads(result.stdout)
    assert "ACME001" in json.dumps(report)
    assert "debugging {not json" in result.stderr


def test_a_rule_that_prints_leaves_the_spec_document_alone(
    tmp_path: Path, layer: Path, monkeypatch
) -> None:
    # spec runs the rules too (its findings per configuration).
    site = tmp_path / "site"
    site.mkdir()
    install_plugin(site, "noisy", "noisy_rules", PRINTING_RULES, "noisy_rules:RULES")
    monkeypatch.syspath_prepend(str(site))
    args = ["spec", "--isolated", "--jobs", "1", "--timeout", "0", "--format", "json"]
    result = CliRunner().invoke(cli, [*args, str(layer)])
    assert json.loads(result.stdout)
    assert "debugging {not json" in result.stderr


RAISING_RULES = '''
from pxr import UsdRender
from usdrender_lint.api import Rule, Severity


class Broken(Rule):
    """Another studio's rule, with a bug."""

    code = "BRK001"
    name = "broken-rule"
    severity = Severity.WARNING
    prim_types = (UsdRender.Product,)

    def check_prim(self, prim, ctx):
        raise KeyError("boom")
        yield


RULES = [Broken]
'''


def test_a_fixture_is_not_failed_by_another_plugin_s_rule(tmp_path: Path, monkeypatch) -> None:
    """check_fixture runs the built-in rules and the rule's own plugin: another
    installed plugin's bug (a rule that raises) is not the fixture's failure."""
    from usdrender_lint.testing import check_fixture

    site = tmp_path / "site"
    site.mkdir()
    install_plugin(site, "acme", "acme_rules", ACME_RULES, "acme_rules:RULES")
    install_plugin(site, "other", "other_rules", RAISING_RULES, "other_rules:RULES")
    monkeypatch.syspath_prepend(str(site))
    fixture = tmp_path / "fail_frame_token.usda"
    fixture.write_text(
        LAYER.replace(
            "#usda 1.0\n", '#usda 1.0\n# expect: ACME001 </Render/beauty> "frame token"\n'
        )
    )
    check_fixture(fixture, "ACME001")
    # The raising rule's own fixtures still fail on it.
    own = tmp_path / "pass_broken.usda"
    own.write_text(LAYER)
    with pytest.raises(KeyError, match="boom"):
        check_fixture(own, "BRK001")


INTERRUPTING_RULES = '''
from pxr import UsdRender
from usdrender_lint.api import Rule, Severity


class Interrupting(Rule):
    """Another studio's rule, raising what no rule should."""

    code = "BRK002"
    name = "interrupting-rule"
    severity = Severity.WARNING
    prim_types = (UsdRender.Product,)

    def check_prim(self, prim, ctx):
        raise {raised}
        yield


RULES = [Interrupting]
'''


@pytest.mark.parametrize("raised", ["KeyboardInterrupt", "GeneratorExit"])
@pytest.mark.parametrize("jobs", [("--jobs", "1", "--timeout", "0"), ("--jobs", "2")])
def test_a_rule_raising_keyboard_interrupt_is_its_internal_error(
    tmp_path: Path, layer: Path, raised: str, jobs: tuple[str, ...]
) -> None:
    # No Ctrl-C raises it in the command (which turns SIGINT into its own exception):
    # the rule's bug. It was click's "Aborted!" and exit 1 with no report in process,
    # "the linter process crashed" in a worker; GeneratorExit a traceback.
    site = tmp_path / "site"
    site.mkdir()
    source = INTERRUPTING_RULES.replace("{raised}", raised)
    install_plugin(site, "intr", "intr_rules", source, "intr_rules:RULES")
    other = tmp_path / "other.usda"
    other.write_text(LAYER)
    args = ["check", "--isolated", "--no-cache", *jobs, "--format", "json", str(layer), str(other)]
    result = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", *args],
        env={**os.environ, "PYTHONPATH": str(site)},
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 1, result.stderr
    assert not result.stderr
    for entry in json.loads(result.stdout)["files"]:
        [internal] = [f for f in entry["findings"] if f["code"] == "UL000"]
        # No message: no ": " (it read "raised MemoryError:  on /Render/...").
        assert f"rule BRK002 (interrupting-rule) raised {raised} on /" in internal["message"]


def test_a_keyboard_interrupt_in_a_rule_stops_a_python_program(
    tmp_path: Path, layer: Path, monkeypatch
) -> None:
    # There Ctrl-C raises KeyboardInterrupt wherever the program is: in a rule too.
    site = tmp_path / "site"
    site.mkdir()
    source = INTERRUPTING_RULES.replace("{raised}", "KeyboardInterrupt")
    install_plugin(site, "intr", "intr_rules", source, "intr_rules:RULES")
    monkeypatch.syspath_prepend(str(site))
    import intr_rules

    from usdrender_lint.engine import Linter

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            Linter([intr_rules.Interrupting()]).lint_path(str(layer))
    finally:
        signal.signal(signal.SIGINT, previous)
