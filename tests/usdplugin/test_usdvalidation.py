"""The UsdValidation plugin: the shipped plugInfo.json follows the registry, the
validators load through OpenUSD's registry and report what the CLI reports,
safe fixes are ValidationFixers, and no exception ever leaves a validator.

USD registers plugins once per process and reads PXR_PLUGINPATH_NAME when its
plugin registry starts, so everything that loads the plugin runs in a
subprocess with the variable set.
"""

from __future__ import annotations

import gc
import json
import os
import stat
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import pytest
from click.testing import CliRunner
from pxr import Sdf, Tf, Usd, UsdRender

from usdrender_lint.api import Rule
from usdrender_lint.cli import cli
from usdrender_lint.engine import Linter
from usdrender_lint.model import Severity
from usdrender_lint.registry import build_registry
from usdrender_lint.running.stage_lints import CheckedLints, StageLints
from usdrender_lint.usdplugin import (
    PLUGIN_NAME,
    DeclarationError,
    plug_info,
    plugin_dir,
    render_plug_info,
    undeclared_rules,
    validator_name,
    write_plug_info,
)
from usdrender_lint.usdplugin.validators import fixer_description

REPO = Path(__file__).parents[2]
FIXTURES = REPO / "tests" / "rules"
SE003_FAIL = FIXTURES / "SE003_data_window_malformed" / "fail_inverted.usda"
RULES = build_registry().rules

pytestmark = pytest.mark.heavy(seconds=38)


def _run_child(script: str, plugin_path: Path, extra_path: Path | None = None, *args: str) -> dict:
    env = dict(os.environ, PXR_PLUGINPATH_NAME=str(plugin_path))
    if extra_path is not None:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(extra_path), env.get("PYTHONPATH")]))
    done = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(script), *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=400,
        cwd=REPO,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


# -- the declaration --------------------------------------------------------------


def test_shipped_plug_info_matches_the_registry() -> None:
    shipped = (plugin_dir() / "plugInfo.json").read_text(encoding="utf-8")
    assert shipped == render_plug_info(RULES), (
        "usdrender_lint/usdplugin/plugInfo.json is out of date with the registered rules: "
        "run 'usdrender-lint plugin-path --write' and commit it"
    )
    assert undeclared_rules(RULES) == []


def test_every_rule_is_declared_with_its_family_and_schema_types() -> None:
    validators = plug_info(RULES)["Plugins"][0]["Info"]["Validators"]
    assert validators.pop("keywords") == [PLUGIN_NAME]
    assert len(validators) == len(RULES)
    for rule in RULES:
        entry = validators[validator_name(rule).split(":", 1)[1]]
        family = rule.code.rstrip("0123456789")
        assert f"{PLUGIN_NAME}:{family}" in entry["keywords"]
        assert entry["doc"].startswith(f"{rule.code} ({rule.name}): ")
        if rule.prim_types:
            assert entry["schemaTypes"], rule.code
            for type_name in entry["schemaTypes"]:
                assert not Tf.Type.FindByName(type_name).isUnknown, type_name
        else:
            assert "schemaTypes" not in entry, rule.code
    assert validators["ResolutionNonPositive"]["schemaTypes"] == ["UsdRenderSettingsBase"]


def _rule(code: str, name: str, **attrs) -> type[Rule]:
    return type(
        name.title().replace("-", ""),
        (Rule,),
        {
            "__doc__": f"{name} summary.",
            "code": code,
            "name": name,
            "severity": Severity.ERROR,
            **attrs,
        },
    )


def test_the_guide_names_every_keyword_and_schema_type_declared() -> None:
    guide = " ".join((REPO / "docs" / "guides" / "usdvalidation.md").read_text().split())
    validators = plug_info(RULES)["Plugins"][0]["Info"]["Validators"]
    declared = [v for name, v in validators.items() if name != "keywords"]
    schema_types = {t for v in declared for t in v.get("schemaTypes", [])}
    assert [t for t in sorted(schema_types) if f"`{t}`" not in guide] == []
    shapes = {
        keyword.replace(rule.code, "<code>").replace(rule.code.rstrip("0123456789"), "<family>")
        for rule in RULES
        for keyword in validators[validator_name(rule).partition(":")[2]]["keywords"]
    }
    assert [s for s in sorted(shapes) if f"`{s}`" not in guide] == []


def test_two_rules_with_one_validator_name_are_refused() -> None:
    # Kebab parts may start with a digit, so "a-1b" and "a1b" both give "A1b".
    with pytest.raises(DeclarationError, match="ZZ001 and ZZ002"):
        plug_info([_rule("ZZ001", "a-1b"), _rule("ZZ002", "a1b")])


def test_a_changed_rule_makes_the_file_stale(tmp_path: Path) -> None:
    write_plug_info(RULES, tmp_path)
    assert undeclared_rules(RULES, tmp_path) == []
    extra = _rule("ZZ003", "extra-check", prim_types=(UsdRender.Var,))
    assert undeclared_rules([*RULES, extra], tmp_path) == ["ZZ003"]


def test_the_wheel_ships_the_plugin() -> None:
    # Verified by building a wheel; this keeps the packaging lines in place.
    setuptools = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert {"usdrender_lint.usdplugin", PLUGIN_NAME} <= set(setuptools["packages"])
    assert "plugInfo.json" in setuptools["package-data"]["usdrender_lint.usdplugin"]
    mapped = REPO / setuptools["package-dir"][PLUGIN_NAME] / "__init__.py"
    assert mapped.is_file()


# -- the command ------------------------------------------------------------------


def test_plugin_path_prints_the_shipped_directory() -> None:
    result = CliRunner().invoke(cli, ["plugin-path", "--check"])
    assert result.exit_code == 0, result.output
    assert result.output.strip() == str(plugin_dir())


def test_plugin_path_write_and_check(tmp_path: Path) -> None:
    target = tmp_path / "plugin"
    stale = CliRunner().invoke(cli, ["plugin-path", "--check", "--dir", str(target)])
    assert stale.exit_code == 1
    assert "--write" in stale.output
    written = CliRunner().invoke(cli, ["plugin-path", "--write", "--dir", str(target)])
    assert written.exit_code == 0, written.output
    assert written.output.strip() == str(target.resolve())
    assert (target / "plugInfo.json").read_text() == render_plug_info(RULES)
    fresh = CliRunner().invoke(cli, ["plugin-path", "--check", "--dir", str(target)])
    assert fresh.exit_code == 0


@pytest.mark.parametrize(
    "content, why",
    [
        (None, "has no plugInfo.json"),
        ("{not json", "plugInfo.json is not JSON declaring the plugin's validators"),
        ('{"Plugins": []}', "plugInfo.json is not JSON declaring the plugin's validators"),
    ],
    ids=["missing", "not-json", "no-validators"],
)
def test_plugin_path_check_says_why_a_folder_is_out_of_date(
    tmp_path: Path, content: str | None, why: str
) -> None:
    # Not "does not declare 73 registered rule(s) (AR001, ...)": the file is the problem.
    target = tmp_path / "plugin"
    target.mkdir()
    if content is not None:
        (target / "plugInfo.json").write_text(content)
    result = CliRunner().invoke(cli, ["plugin-path", "--check", "--dir", str(target)])
    assert result.exit_code == 1
    assert why in result.stderr and "does not declare" not in result.stderr
    assert result.stderr.count("\n") == 1


def test_plugin_path_write_error_is_one_plain_line(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("")
    target = tmp_path / "file" / "plugin"  # below a file: cannot be created
    result = CliRunner().invoke(cli, ["plugin-path", "--write", "--dir", str(target)])
    assert result.exit_code == 2
    assert result.stderr == (
        f"usdrender-lint: error: {target}: cannot write plugInfo.json: Not a directory\n"
    )


# -- the per-stage lint the validators share ---------------------------------------


def test_one_lint_per_stage_state() -> None:
    built = []

    def factory():
        built.append(1)
        linter = Linter([rule() for rule in RULES], known_rules=RULES)
        original = linter.run_stage
        calls = built

        def counted(stage, file=None):
            calls.append(stage)
            return original(stage, file)

        linter.run_stage = counted
        return linter

    made: list = []

    def linter_for(stage):  # the linter is built once (StageLints asks per stage)
        if not made:
            made.append(factory())
        return made[0]

    lints = StageLints(linter_for)
    stage = Usd.Stage.Open(str(SE003_FAIL))
    first = lints.findings(stage)
    # Another Python handle on the same stage shares the lint.
    assert lints.findings(stage.GetPseudoRoot().GetStage()) is first
    assert len(built) == 2  # one linter, one lint
    assert ("SE003", "/Render/Settings.dataWindowNDC") in {
        (t.finding.code, t.finding.location.path) for t in first
    }
    # An edit (here on the session layer) makes the next call lint again.
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        stage.GetPrimAtPath("/Render/Settings").GetAttribute("dataWindowNDC").Set(
            (0.0, 0.0, 1.0, 1.0)
        )
    again = lints.findings(stage)
    assert len(built) == 3
    assert "SE003" not in {t.finding.code for t in again}


def test_a_stage_the_host_closed_is_not_kept_open(tmp_path: Path) -> None:
    """Every per-stage cache lets a stage go when its host drops it: a stage
    kept alive keeps its layers open, and the next stage opened on the file
    would get their old content, not what is on disk now."""
    shot = tmp_path / "shot.usda"
    shot.write_text(SE003_FAIL.read_text())
    lints = CheckedLints()
    stage = Usd.Stage.Open(str(shot))
    assert "SE003" in {t.finding.code for t in lints.reported(stage)}
    assert lints.failures.first(stage, "a validator")
    del stage
    gc.collect()
    assert Sdf.Layer.Find(str(shot)) is None
    shot.write_text(shot.read_text().replace("= (0.8, 0, 0.2, 1)", "= (0.2, 0, 0.8, 1)"))
    assert "SE003" not in {t.finding.code for t in lints.reported(Usd.Stage.Open(str(shot)))}


# -- through OpenUSD's registry (subprocesses) -------------------------------------

_SAME_AS_CLI = """
import json, sys
from pathlib import Path
from pxr import Sdf, Tf, Usd, UsdValidation
from usdrender_lint.registry import build_registry
from usdrender_lint.running.pipeline import Request, run
from usdrender_lint.usdplugin import validator_name

registry = UsdValidation.ValidationRegistry()
declared = sorted(str(m.name) for m in registry.GetValidatorMetadataForKeyword("usdRenderLint"))
rules = build_registry().rules
loaded = [registry.GetOrLoadValidatorByName(validator_name(rule)) for rule in rules]
context = UsdValidation.ValidationContext([v for v in loaded if v is not None])
# The validators report what `check FILE` does, with the configuration it finds.
def check(path):
    return run(Request((str(path),), jobs=1, timeout=None, progress=False)).report.findings

def site_path(site):
    if site.IsProperty():
        return str(site.GetProperty().GetPath())
    if site.IsPrim() and not site.GetPrim().IsPseudoRoot():
        return str(site.GetPrim().GetPath())
    return ""

def abstract_typed_prim(stage, where):
    prim = stage.GetPrimAtPath(Sdf.Path(where).GetPrimPath()) if where else None
    if not prim:
        return False
    registered = Usd.SchemaRegistry.GetTypeFromName(prim.GetTypeName())
    return not registered.isUnknown and prim.GetPrimTypeInfo().GetSchemaType().isUnknown

mismatches, checked, abstract_typed = [], 0, []
paths = [Path(p) for p in sys.argv[1:]] or [
    p for p in sorted(Path("tests/rules").glob("*/*.usda"))
    if p.name.startswith(("pass_", "fail_")) and not p.name.endswith(".fixed.usda")
]
for path in paths:
    cli = {(f.code, f.location.path or "") for f in check(path)}
    try:
        stage = Usd.Stage.Open(str(path))
    except Tf.ErrorException:
        # usd-core refuses the file (ST001): there is no stage to validate.
        assert {code for code, _ in cli} == {"ST001"}, (path, cli)
        continue
    validated = {(e.GetName(), site_path(e.GetSites()[0])) for e in context.Validate(stage)}
    checked += 1
    # USD gives a prim typed with an abstract schema (def RenderSettingsBase) no
    # schema type, so UsdValidation never hands it to a schemaTypes validator; the
    # engine dispatches by type name and runs the rules on it.
    abstract = {pair for pair in cli - validated if abstract_typed_prim(stage, pair[1])}
    abstract_typed.extend(sorted(abstract))
    if validated != cli - abstract:
        mismatches.append([str(path), sorted(cli - validated), sorted(validated - cli)])

# The errors carry the offending property as their site, in the opinion's layer.
stage = Usd.Stage.Open("tests/rules/SE003_data_window_malformed/fail_inverted.usda")
se003 = [e for e in context.Validate(stage) if e.GetName() == "SE003"][0]
site = se003.GetSites()[0]
fixers = {e.GetName(): [f.name for f in e.GetFixers()] for e in context.Validate(stage)}
print(json.dumps({
    "declared": declared,
    "loaded": sum(v is not None for v in loaded),
    "checked": checked,
    "mismatches": mismatches,
    "abstract_typed": abstract_typed,
    "site_is_property": site.IsProperty(),
    "site_layer": site.GetLayer().realPath if site.GetLayer() else None,
    "se003_type": str(se003.GetType()),
    "se003_validator": str(se003.GetValidator().GetMetadata().name),
    "fixers": fixers,
}))
"""


def test_validators_load_by_keyword_and_name_and_match_the_cli_on_every_fixture() -> None:
    got = _run_child(_SAME_AS_CLI, plugin_dir())
    assert got["declared"] == sorted(validator_name(rule) for rule in RULES)
    assert got["loaded"] == len(RULES)
    assert got["checked"] > 250  # every pass_/fail_ fixture USD can open
    assert got["mismatches"] == []
    assert got["abstract_typed"] == []
    assert got["site_is_property"] is True
    assert got["site_layer"] == str(SE003_FAIL.resolve())
    assert got["se003_type"].endswith("Error")
    assert got["se003_validator"] == f"{PLUGIN_NAME}:DataWindowMalformed"
    # ST003's fix is safe: a fixer; SE003's is unsafe: none.
    assert got["fixers"]["ST003"] == ["RenderSettingsPathMissingFix"]
    assert got["fixers"]["SE003"] == []


_FIXER = """
import json, shutil, sys
from pxr import Usd, UsdValidation
work = sys.argv[1]
registry = UsdValidation.ValidationRegistry()
validator = registry.GetOrLoadValidatorByName("usdRenderLint:RenderSettingsPathMissing")
stage = Usd.Stage.Open(work)
error = validator.Validate(stage)[0]
fixer = error.GetFixers()[0]
target = Usd.EditTarget(stage.GetRootLayer())
can = fixer.CanApplyFix(error, target)
applied = fixer.ApplyFix(error, target)
print(json.dumps({"can": can, "applied": applied, "after": len(validator.Validate(stage))}))
"""


def test_a_safe_fix_applies_through_validation_fixer(tmp_path: Path) -> None:
    work = tmp_path / "shot.usda"
    work.write_text(SE003_FAIL.read_text())
    got = _run_child(_FIXER, plugin_dir(), None, str(work))
    # usd-core 26.11's ApplyFix saves the edit target's layer after the fix.
    assert got == {"can": True, "applied": True, "after": 0}
    assert 'renderSettingsPrimPath = "/Render/Settings"' in work.read_text()


_RAISING_RULES = '''
from pxr import UsdRender
from usdrender_lint.api import Rule
from usdrender_lint.model import Severity


class PrimExplodes(Rule):
    """Raises on every RenderSettings."""

    code = "ZZ901"
    name = "prim-explodes"
    severity = Severity.ERROR
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim, ctx):
        raise RuntimeError("boom")


class StageExplodes(Rule):
    """Raises once per stage."""

    code = "ZZ902"
    name = "stage-explodes"
    severity = Severity.ERROR

    def check_stage(self, ctx):
        raise RuntimeError("bang")
        yield


RAISING = (PrimExplodes, StageExplodes)
'''

_NEVER_RAISES = """
import json
from pxr import Sdf, Tf, Usd, UsdValidation
from usdrender_lint.engine import Linter
registry = UsdValidation.ValidationRegistry()
names = [str(m.name) for m in registry.GetValidatorMetadataForKeyword("usdRenderLint")]
context = UsdValidation.ValidationContext(registry.GetOrLoadValidatorsByName(names))
RULE_DIR = "tests/rules/"
SE003 = RULE_DIR + "SE003_data_window_malformed/fail_inverted.usda"
errors = context.Validate(Usd.Stage.Open(SE003))
raised = sorted(
    [str(e.GetValidator().GetMetadata().name), e.GetName()]
    for e in errors
    if e.GetName() == "UL000"
)
codes = sorted({e.GetName() for e in errors})

# The whole lint failing: each validator reports it, Validate still returns.
def broken(self, stage, file=None):
    raise MemoryError("no more")
Linter.run_stage = broken
SE001 = RULE_DIR + "SE001_resolution_non_positive/pass_traps.usda"
failures = context.Validate(Usd.Stage.Open(SE001))

# The premise: one raising Python validator makes usd-core's Validate raise.
def explode(stage, time_range):
    raise RuntimeError("plain validator")
metadata = UsdValidation.ValidatorMetadata(name="plain:Explodes", doc="raises", keywords=["plain"])
registry.RegisterStageValidator(metadata, explode)
plain = UsdValidation.ValidationContext([registry.GetOrLoadValidatorByName("plain:Explodes")])
try:
    plain.Validate(Usd.Stage.CreateInMemory())
    premise = False
except RuntimeError as exc:  # the validator's own exception comes out of Validate
    premise = "plain validator" in str(exc)
print(json.dumps({
    "raised": raised, "codes": codes, "premise": premise,
    "failures": sorted({e.GetName() for e in failures}), "failure_count": len(failures),
    "message": failures[0].GetMessage() if failures else "",
}))
"""


def _installed(site: Path, module: str, attribute: str) -> None:
    """A rule plugin in ``site`` (put on PYTHONPATH), as pip installs one."""
    info = site / f"{module}-0.1.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {module}\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(
        f"[usdrender_lint.rules]\n{module} = {module}:{attribute}\n"
    )


def test_a_raising_rule_never_makes_validate_raise(tmp_path: Path) -> None:
    (tmp_path / "raising_rules.py").write_text(_RAISING_RULES)
    _installed(tmp_path, "raising_rules", "RAISING")
    sys.path.insert(0, str(tmp_path))
    try:
        import raising_rules

        write_plug_info(RULES + raising_rules.RAISING, tmp_path / "plugin")
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop("raising_rules", None)
    got = _run_child(_NEVER_RAISES, tmp_path / "plugin", extra_path=tmp_path)
    assert got["premise"] is True
    # Each raising rule is one internal error of its own validator ...
    assert got["raised"] == [
        [f"{PLUGIN_NAME}:PrimExplodes", "UL000"],
        [f"{PLUGIN_NAME}:StageExplodes", "UL000"],
    ]
    # ... and the other validators' results survive.
    assert {"SE003", "SE015"} <= set(got["codes"])
    assert got["failures"] == ["usdRenderLintFailure"]
    assert got["failure_count"] >= 1
    assert "MemoryError: no more" in got["message"]


_BOTH_HOOKS_RULES = '''
from pxr import UsdRender
from usdrender_lint.api import Diagnostic, Rule
from usdrender_lint.model import Severity


class BothHooks(Rule):
    """Checks each RenderSettings and the stage as a whole."""

    code = "ZZ903"
    name = "both-hooks"
    severity = Severity.WARNING
    prim_types = (UsdRender.Settings,)

    def check_prim(self, prim, ctx):
        yield Diagnostic(message="from check_prim", at=prim)

    def check_stage(self, ctx):
        yield Diagnostic(message="from check_stage", at=None)


RULES = (BothHooks,)
'''

_BOTH_HOOKS = """
import json
from pxr import Usd, UsdValidation
registry = UsdValidation.ValidationRegistry()
validator = registry.GetOrLoadValidatorByName("usdRenderLint:BothHooks")
stage = Usd.Stage.Open("tests/rules/SE003_data_window_malformed/fail_inverted.usda")
errors = UsdValidation.ValidationContext([validator]).Validate(stage)
print(json.dumps(sorted(e.GetMessage() for e in errors)))
"""


def test_a_rule_with_both_hooks_reports_its_stage_findings(tmp_path: Path) -> None:
    # USD calls a prim validator only on prims of its schemaTypes: a rule that
    # also has check_stage is a stage validator, or its stage findings are lost.
    (tmp_path / "both_rules.py").write_text(_BOTH_HOOKS_RULES)
    _installed(tmp_path, "both_rules", "RULES")
    sys.path.insert(0, str(tmp_path))
    try:
        import both_rules

        write_plug_info(RULES + both_rules.RULES, tmp_path / "plugin")
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop("both_rules", None)
    messages = _run_child(_BOTH_HOOKS, tmp_path / "plugin", extra_path=tmp_path)
    stage = Usd.Stage.Open(str(SE003_FAIL))
    settings = [p for p in stage.Traverse() if p.IsA(UsdRender.Settings)]
    assert settings
    assert messages == ["from check_prim"] * len(settings) + ["from check_stage"]


_PLUGIN_FAILS = """
import json
from pxr import Sdf, Usd, UsdValidation
import usdrender_lint.registry as registry_module

def failing(entry_points=None):
    raise registry_module.RegistryError("rule plugin 'acme' (acme_rules:RULES) failed to load")
registry_module.build_registry = failing
layer = Sdf.Layer.CreateAnonymous(".usda")
layer.ImportFromString('''#usda 1.0
def RenderSettings "Settings" (
    customData = { dictionary usdrender_lint = { string[] ignore = ["ACME001"] } }
)
{
}
''')
registry = UsdValidation.ValidationRegistry()
names = [str(m.name) for m in registry.GetValidatorMetadataForKeyword("usdRenderLint")]
context = UsdValidation.ValidationContext(registry.GetOrLoadValidatorsByName(names))
errors = context.Validate(Usd.Stage.Open(layer))
print(json.dumps(sorted({e.GetName() for e in errors})))
"""


def test_a_plugin_that_fails_to_load_never_calls_its_suppressions_unused() -> None:
    # Its rules are missing, so "no rule has this code or name" would be false, and
    # UL001's safe fix would delete the suppression.
    names = _run_child(_PLUGIN_FAILS, plugin_dir())
    assert "UL001" not in names
    assert "usdRenderLintFailure" in names


def test_a_declared_validator_without_a_rule_reports_why(tmp_path: Path) -> None:
    # A stale plugInfo.json declares a rule that is no longer registered.
    ghost = _rule("ZZ904", "ghost-check")
    write_plug_info([*RULES, ghost], tmp_path)
    script = """
    import json
    from pxr import Usd, UsdValidation
    registry = UsdValidation.ValidationRegistry()
    validator = registry.GetOrLoadValidatorByName("usdRenderLint:GhostCheck")
    errors = validator.Validate(Usd.Stage.CreateInMemory())
    print(json.dumps([e.GetMessage() for e in errors]))
    """
    messages = _run_child(script, tmp_path)
    assert len(messages) == 1
    assert "plugin-path --write" in messages[0]


def test_sdf_paths_of_sites_round_trip() -> None:
    # A stage-wide finding's site is the pseudo-root (no prim or property path).
    from usdrender_lint.model import Finding, Location
    from usdrender_lint.usdplugin.validators import to_error

    stage = Usd.Stage.CreateInMemory()
    finding = Finding("ST003", "x", Severity.INFO, "m", Location("f", None, None))
    site = to_error(stage, finding).GetSites()[0]
    assert site.GetPrim().GetPath() == Sdf.Path.absoluteRootPath


def test_validators_match_the_cli_on_corpus_files(shared_dir: Path) -> None:
    files = sorted((shared_dir / "corpus" / "files").rglob("*.usd*"))
    # Every real file with render prims (a few seconds): the validators see what the CLI sees.
    render = [str(p) for p in files if p.suffix == ".usda" and b"RenderSettings" in p.read_bytes()]
    if not render:
        pytest.skip("no corpus file with RenderSettings")
    got = _run_child(_SAME_AS_CLI, plugin_dir(), None, *render)
    assert got["mismatches"] == []
    # The one known difference, set aside by the child: findings on prims typed with an
    # abstract schema (maya-usd's materialAssignment.usda has `def RenderSettingsBase`).
    assert got["checked"] >= len(render) * 0.8


# -- fixes as minimal text edits -----------------------------------------------------

_FIX_ALL = """
import json, sys
from pxr import Sdf, Usd, UsdValidation
work, dirty = sys.argv[1], sys.argv[2] == "dirty"
registry = UsdValidation.ValidationRegistry()
validators = [registry.GetOrLoadValidatorByName(m.name)
              for m in registry.GetValidatorMetadataForKeyword("usdRenderLint")]
context = UsdValidation.ValidationContext(validators)
stage = Usd.Stage.Open(work)
if dirty:  # an unsaved edit: the fixer can only edit through Sdf
    stage.GetRootLayer().documentation = "edited in memory"
applied, offered = [], []
for _ in range(10):  # fix, validate again, until no fixer applies
    fixed = False
    for error in context.Validate(stage):
        for fixer in error.GetFixers():
            target = Usd.EditTarget(stage.GetRootLayer())
            if not fixer.CanApplyFix(error, target):
                continue
            offered.append(str(error.GetName()))
            if fixer.ApplyFix(error, target):
                applied.append(str(error.GetName()))
                fixed = True
                break
        if fixed:
            break
    if not fixed:
        break
print(json.dumps({
    "applied": applied,
    "offered": offered,
    "dirty_after": stage.GetRootLayer().dirty,
    "descriptions": sorted({f.description for e in context.Validate(stage) for f in e.GetFixers()}),
}))
"""


def test_a_validation_fix_is_the_text_edit_of_check_fix(tmp_path: Path) -> None:
    """The UsdValidation fixers leave the layer's text exactly as `check --fix`
    does: comments, blank lines and layout kept."""
    source = REPO / "examples" / "broken_shot" / "shot.usda"
    by_cli = tmp_path / "cli" / "shot.usda"
    by_fixer = tmp_path / "fixer" / "shot.usda"
    for copy in (by_cli, by_fixer):
        copy.parent.mkdir()
        copy.write_text(source.read_text())
    result = CliRunner().invoke(cli, ["check", "--isolated", "--fix", str(by_cli)])
    assert result.exit_code in (0, 1), result.output
    got = _run_child(_FIX_ALL, plugin_dir(), None, str(by_fixer), "clean")
    assert sorted(got["applied"]) == sorted(got["offered"]) == ["CA004", "SE007"]
    assert got["dirty_after"] is False
    assert by_fixer.read_text() == by_cli.read_text()
    assert by_fixer.read_text() != source.read_text()
    assert "# CA004: the camera relationship targets the rig" in by_fixer.read_text()
    # What the fixers say they do, where it can only be an Sdf edit.
    assert got["descriptions"] == [] or all("through Sdf" in d for d in got["descriptions"])
    assert "through Sdf" in fixer_description(RULES[0])


def test_a_validation_fix_of_a_layer_with_hard_links_is_not_applied(tmp_path: Path) -> None:
    """--fix leaves a file with several hard links alone (a rename would split
    them); the fixer made an Sdf edit instead, which ApplyFix's Save wrote as
    Sdf's export: the links split, the comments and the mode bits gone."""
    work = tmp_path / "shot.usda"
    work.write_text((REPO / "examples" / "broken_shot" / "shot.usda").read_text())
    work.chmod(0o751)
    other = tmp_path / "other-name.usda"
    os.link(work, other)
    before = work.read_bytes()
    got = _run_child(_FIX_ALL, plugin_dir(), None, str(work), "clean")
    assert got["applied"] == []
    assert got["offered"] == []  # CanApplyFix says so before ApplyFix is tried
    assert work.read_bytes() == before
    assert work.stat().st_ino == other.stat().st_ino
    assert stat.S_IMODE(work.stat().st_mode) == 0o751


def test_a_validation_fix_of_a_usdz_package_is_not_applied(tmp_path: Path) -> None:
    """--fix leaves a .usdz alone, and USD cannot save a package layer: the
    fixer made an Sdf edit that ApplyFix's save then raised on (a Tf error out
    of ApplyFix), leaving the layer dirty. Now it is not applied, and
    CanApplyFix says so (it answered true)."""
    from pxr import UsdUtils

    source = tmp_path / "shot.usda"
    source.write_text((REPO / "examples" / "broken_shot" / "shot.usda").read_text())
    package = tmp_path / "shot.usdz"
    assert UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(str(source)), str(package))
    before = package.read_bytes()
    got = _run_child(_FIX_ALL, plugin_dir(), None, str(package), "clean")
    assert got["offered"] == []
    assert got["applied"] == []
    assert got["dirty_after"] is False
    assert package.read_bytes() == before


def test_a_validation_fix_of_a_layer_with_unsaved_edits_goes_through_sdf(tmp_path: Path) -> None:
    """The documented limit: with unsaved edits in the layer the fix is an Sdf
    edit, and ApplyFix's Save writes Sdf's export (comments gone)."""
    work = tmp_path / "shot.usda"
    work.write_text((REPO / "examples" / "broken_shot" / "shot.usda").read_text())
    got = _run_child(_FIX_ALL, plugin_dir(), None, str(work), "dirty")
    assert sorted(got["applied"]) == ["CA004", "SE007"]
    text = work.read_text()
    assert "edited in memory" in text and "# CA004" not in text
    assert "rel camera = </World/camRig/shotCam>" in text


# -- the project's configuration -------------------------------------------------------

_CONFIGURED = """
import json, sys
from pxr import Usd, UsdValidation
registry = UsdValidation.ValidationRegistry()
names = [str(m.name) for m in registry.GetValidatorMetadataForKeyword("usdRenderLint")]
context = UsdValidation.ValidationContext(registry.GetOrLoadValidatorsByName(names))
severity = {"Error": "error", "Warn": "warning", "Info": "info"}
stage = Usd.Stage.Open(sys.argv[1])
target = Usd.EditTarget(stage.GetRootLayer())
errors, fixable = [], []
for error in context.Validate(stage):
    site = error.GetSites()[0]
    where = site.GetProperty() if site.IsProperty() else site.GetPrim()
    path = str(where.GetPath()) if not site.IsPrim() or not where.IsPseudoRoot() else None
    kind = severity[str(error.GetType()).rsplit(".", 1)[-1]]
    errors.append([str(error.GetName()), path, kind, error.GetMessage()])
    if any(f.CanApplyFix(error, target) for f in error.GetFixers()):
        fixable.append(str(error.GetName()))
print(json.dumps({"errors": sorted(errors), "fixable": sorted(fixable)}))
"""

#: A project configuration that changes what check reports on the example shot in
#: every way a key can: a pinned profile (KA003 appears), an ignored rule (CA003),
#: a severity (PR004), a per-path ignore (SE003) and an unfixable rule (CA004).
_PROJECT = """\
profile = "karma"
ignore = ["CA003"]
unfixable = ["CA004"]

[severity]
PR004 = "warning"

[per-path-ignores]
"shot.usda" = ["SE003"]
"""


def test_validators_report_and_fix_what_check_does_under_the_projects_configuration(
    tmp_path: Path,
) -> None:
    """The validators read the configuration found from the file's folder, as
    check (and the Asset Validator) do. They read none: they reported CA003 and
    SE003, PR004 as an error, no KA003, and CanApplyFix said yes to CA004's fix,
    which check --fix leaves alone."""
    shot = tmp_path / "shot.usda"
    shot.write_text((REPO / "examples" / "broken_shot" / "shot.usda").read_text())
    (tmp_path / "lighting_wip.usda").write_text(
        (REPO / "examples" / "broken_shot" / "lighting_wip.usda").read_text()
    )
    (tmp_path / ".usdrender-lint.toml").write_text(_PROJECT)
    done = CliRunner().invoke(cli, ["check", "--no-cache", "--format", "json", str(shot)])
    findings = json.loads(done.stdout)["files"][0]["findings"]
    expected = sorted([f["code"], f["path"], f["severity"], f["message"]] for f in findings)
    assert {"KA003", "CA004", "SE007"} <= {f["code"] for f in findings}
    # What check --fix applies: a safe fix of a rule the configuration leaves fixable.
    fixed = {f["code"] for f in findings if f["fix"] and f["fix"]["safe"]} - {"CA004"}
    got = _run_child(_CONFIGURED, plugin_dir(), None, str(shot))
    assert got["errors"] == expected
    assert set(got["fixable"]) == fixed == {"SE007"}


def test_a_configuration_that_cannot_be_read_is_one_error_per_stage(tmp_path: Path) -> None:
    shot = tmp_path / "shot.usda"
    shot.write_text(SE003_FAIL.read_text())
    (tmp_path / ".usdrender-lint.toml").write_text('no-such-key = "x"\n')
    got = _run_child(_CONFIGURED, plugin_dir(), None, str(shot))
    [error] = got["errors"]
    assert error[0] == "usdRenderLintFailure"
    assert "no-such-key" in error[3] and ".usdrender-lint.toml" in error[3]


_TWICE = """
import json, sys
from pxr import Usd, UsdValidation
registry = UsdValidation.ValidationRegistry()
names = [str(m.name) for m in registry.GetValidatorMetadataForKeyword("usdRenderLint")]
context = UsdValidation.ValidationContext(registry.GetOrLoadValidatorsByName(names))
stage = Usd.Stage.Open(sys.argv[1])
print(json.dumps([sorted(str(e.GetName()) for e in context.Validate(stage)) for _ in range(3)]))
"""


def test_a_configuration_that_cannot_be_read_is_one_error_each_time_a_stage_is_validated(
    tmp_path: Path,
) -> None:
    # A host validating the stage it keeps open again got no error, and no
    # finding: the stage looked clean.
    shot = tmp_path / "shot.usda"
    shot.write_text(SE003_FAIL.read_text())
    (tmp_path / ".usdrender-lint.toml").write_text('no-such-key = "x"\n')
    got = _run_child(_TWICE, plugin_dir(), None, str(shot))
    assert got == [["usdRenderLintFailure"]] * 3


_EDITED = """
import json, os, sys
from pxr import Usd, UsdValidation
registry = UsdValidation.ValidationRegistry()
names = [str(m.name) for m in registry.GetValidatorMetadataForKeyword("usdRenderLint")]
context = UsdValidation.ValidationContext(registry.GetOrLoadValidatorsByName(names))
shot, config = sys.argv[1], sys.argv[2]
stage = Usd.Stage.Open(shot)
seen = [sorted({str(e.GetName()) for e in context.Validate(stage)})]
before = os.stat(config)
with open(config, "r+") as file:  # in place, the same size, its time set back
    file.write('ignore = ["SE003"]\\n')
os.utime(config, ns=(before.st_atime_ns, before.st_mtime_ns))
seen.append(sorted({str(e.GetName()) for e in context.Validate(stage)}))
seen.append(sorted({str(e.GetName()) for e in context.Validate(Usd.Stage.Open(shot))}))
print(json.dumps(seen))
"""


def test_a_configuration_edited_between_two_validations_is_read_again(tmp_path: Path) -> None:
    # A host keeps running, and its open stage, while its user edits the project's
    # configuration: the next validation follows the file, as check run again does.
    shot = tmp_path / "shot.usda"
    shot.write_text(SE003_FAIL.read_text())
    config = tmp_path / ".usdrender-lint.toml"
    config.write_text('ignore = ["SE004"]\n')
    first, same_stage, new_stage = _run_child(_EDITED, plugin_dir(), None, str(shot), str(config))
    assert "SE003" in first
    assert "SE003" not in new_stage
    assert same_stage == new_stage
