"""Golden tests of every fixable rule: ``check --fix`` on a copy of a fail
fixture gives exactly its goldens, and a second ``--fix`` changes nothing.

``fail_X.fixed.usda`` beside ``fail_X.usda`` is its fixed root layer and
``fail_X--L.fixed.usda`` the fixed supporting layer ``L.usda`` (a fix edits the
layer holding the strongest opinion); every layer without a golden must come
out unchanged. To (re)write the goldens after a deliberate change to a fix,
run with USDRENDER_LINT_WRITE_GOLDENS=1.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner
from pxr import Sdf, Usd

from usdrender_lint.cli import cli
from usdrender_lint.engine import Linter, open_stage
from usdrender_lint.fixing.overlay import composed_stage
from usdrender_lint.registry import build_registry

pytestmark = pytest.mark.heavy(seconds=12)

FIXTURES = Path(__file__).parents[1] / "rules"
GOLDEN_SUFFIX = ".fixed.usda"
WRITE_GOLDENS = os.environ.get("USDRENDER_LINT_WRITE_GOLDENS", "") not in ("", "0")
FIXABLE = {rule.code: rule for rule in build_registry().rules if rule.fix_safety != "none"}
#: Options a pipeline configures before these rules offer a fix (catalog:
#: "none, pipeline template / default vars" unless configured).
RULE_CONFIG = {
    "PR001": '[rules.PR001]\nname-template = "renders/{prim}.exr"\n',
    "PR008": '[rules.PR008]\nalpha-var = "/Render/Vars/alpha"\n',
}


def _folder(code: str) -> Path:
    (folder,) = FIXTURES.glob(f"{code}_*")
    return folder


def _source_of(golden: Path) -> Path:
    """The fail fixture a golden belongs to."""
    stem = golden.name[: -len(GOLDEN_SUFFIX)]
    return golden.with_name(stem.split("--")[0] + ".usda")


def _goldens(fail: Path) -> dict[str, Path]:
    """The goldens of a fail fixture, by the name of the layer each one fixes."""
    found = {fail.name: fail.with_name(fail.stem + GOLDEN_SUFFIX)}
    for golden in fail.parent.glob(f"{fail.stem}--*{GOLDEN_SUFFIX}"):
        layer = golden.name[len(fail.stem) + 2 : -len(GOLDEN_SUFFIX)] + ".usda"
        found[layer] = golden
    return {layer: golden for layer, golden in found.items() if golden.is_file()}


def _cases():
    for code in sorted(FIXABLE):
        folder = _folder(code)
        fails = sorted(folder.glob("fail_*.usda"))
        fails = [f for f in fails if not f.name.endswith(GOLDEN_SUFFIX)]
        for fail in fails:
            if WRITE_GOLDENS or _goldens(fail):
                yield pytest.param(code, fail, id=f"{code}/{fail.name}")


def canonical(path: Path) -> str:
    """A layer as Sdf exports it: formatting and comments do not count."""
    return Sdf.Layer.OpenAsAnonymous(str(path)).ExportToString()


def copy_fixture(fail: Path, destination: Path) -> Path:
    """The fail file and its folder's supporting layers (not the other fixtures)."""
    for path in fail.parent.iterdir():
        supporting = path.is_file() and not path.name.startswith(("pass_", "fail_"))
        if (supporting and path.suffix.startswith(".usd")) or path == fail:
            shutil.copy(path, destination / path.name)
    return destination / fail.name


def run_fix(code: str, path: Path, *extra: str):
    args = ["check", "--jobs", "1", "--timeout", "0", "--select", code, "--format", "json"]
    if code in RULE_CONFIG:
        config = path.parent / "fix-config.toml"
        config.write_text(RULE_CONFIG[code], encoding="utf-8")
        args += ["--config", str(config)]
    else:
        args.append("--isolated")
    if FIXABLE[code].fix_safety == "unsafe":
        args.append("--unsafe-fixes")
    fix = ["--fix"] if not extra else []
    result = CliRunner().invoke(cli, [*args, *fix, *extra, str(path)])
    assert result.exit_code in (0, 1), result.output
    return json.loads(result.stdout)


def _layers(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.suffix.startswith(".usd")}


@pytest.mark.parametrize(("code", "fail"), list(_cases()))
def test_fix_matches_golden(code: str, fail: Path, tmp_path: Path) -> None:
    path = copy_fixture(fail, tmp_path)
    before = _layers(tmp_path)
    document = run_fix(code, path)
    applied = [fix for fix in document["fixes"] if fix["applied"]]
    changed = {name for name, data in _layers(tmp_path).items() if before[name] != data}
    if WRITE_GOLDENS:
        for layer in changed if applied else ():
            name = fail.stem if layer == fail.name else f"{fail.stem}--{Path(layer).stem}"
            golden = fail.with_name(name + GOLDEN_SUFFIX)
            golden.write_text(canonical(tmp_path / layer), encoding="utf-8")
        pytest.skip("goldens written")
    goldens = _goldens(fail)
    assert applied, f"{fail.name}: no {code} fix was applied"
    assert {fix["code"] for fix in document["fixes"]} == {code}
    assert changed == set(goldens), f"--fix edited {sorted(changed)}, goldens: {sorted(goldens)}"
    for layer, golden in goldens.items():
        assert canonical(tmp_path / layer) == canonical(golden), layer
    # A fix silences the finding it was offered for.
    remaining = {(f["code"], f["path"]) for r in document["files"] for f in r["findings"]}
    assert not {(fix["code"], fix["path"]) for fix in applied} & remaining
    # Idempotent: fixing the fixed files changes nothing and applies nothing.
    fixed = _layers(tmp_path)
    again = run_fix(code, path)
    assert _layers(tmp_path) == fixed
    assert [fix for fix in again["fixes"] if fix["applied"]] == []


def test_every_fixable_rule_has_a_golden() -> None:
    missing = [code for code in FIXABLE if not list(_folder(code).glob(f"fail_*{GOLDEN_SUFFIX}"))]
    assert not missing, f"fixable rules without a fail_*{GOLDEN_SUFFIX} golden: {missing}"


def test_every_golden_has_its_fail_fixture() -> None:
    orphans = [
        golden.relative_to(FIXTURES)
        for golden in FIXTURES.glob(f"*/*{GOLDEN_SUFFIX}")
        if not _source_of(golden).is_file()
    ]
    assert not orphans


@pytest.mark.parametrize("rule", build_registry().rules, ids=lambda rule: rule.code)
def test_offered_fixes_match_the_rule_fix_class(rule) -> None:
    """Safe and conditional rules offer safe fixes, unsafe rules unsafe ones,
    and a rule whose class is "none" offers none (checked on its fail fixtures)."""
    linter = Linter([rule()])
    offered = []
    for fail in sorted(_folder(rule.code).glob("fail_*.usda")):
        if fail.name.endswith(GOLDEN_SUFFIX):
            continue
        opened = open_stage(str(fail))
        if opened.stage is not None:
            offered += list(linter.run_stage(opened.stage).fixes.values())
    if rule.fix_safety == "none":
        assert offered == []
    else:
        assert {fix.safe for fix in offered} <= {rule.fix_safety != "unsafe"}


@pytest.mark.parametrize(("code", "fail"), list(_cases()))
def test_fix_to_gives_what_fix_gives(code: str, fail: Path, tmp_path: Path) -> None:
    """The --fix-to layer, as the stage's new root, composes exactly like the
    --fix result, and silences the same findings; the sources stay as they are."""
    (tmp_path / "in_place").mkdir()
    (tmp_path / "overlay").mkdir()
    fixed = copy_fixture(fail, tmp_path / "in_place")
    path = copy_fixture(fail, tmp_path / "overlay")
    before = _layers(tmp_path / "overlay")
    overrides = tmp_path / "overlay" / "overrides.usda"
    document = run_fix(code, path, "--fix-to", str(overrides))
    written = {"overrides.usda": overrides.read_bytes()} if overrides.exists() else {}
    assert _layers(tmp_path / "overlay") == before | written
    refused = [fix["reason"] for fix in document["fixes"] if not fix["applied"]]
    # A retyped weaker spec (SE016 reports it under any stronger opinion) is the
    # one change no override can make.
    assert all("cannot be written as an override" in reason for reason in refused), refused
    run_fix(code, fixed)
    if refused:
        return
    stages = Usd.Stage.Open(str(overrides)), Usd.Stage.Open(str(fixed))
    assert composed_stage(stages[0]) == composed_stage(stages[1])
    remaining = {(f["code"], f["path"]) for r in document["files"] for f in r["findings"]}
    applied = {(fix["code"], fix["path"]) for fix in document["fixes"] if fix["applied"]}
    assert not applied & remaining


#: Fixes whose result other rules rightly judge anew, by the fixing rule: a finding
#: that appears where none was is what the fix corrects, not a fault it makes.
NEW_FINDINGS_EXPECTED = {
    # With a usable camera at last, CA006 compares its aperture with the image.
    "CA001": {"CA006"},
    "CA004": {"CA006"},
    # The swapped window is valid and crops the image: the crop's info.
    "SE003": {"SE005"},
    # The retyped fileName is now read, and names no file.
    "SE016": {"PA004"},
    # The moved prims are judged at their new paths.
    "ST008": {"CA001", "PA001", "PA007", "PR001", "VA001"},
    # The removed arc no longer hides the prims' own problems.
    "ST002": {"PR001", "PR004", "SE015", "ST002", "ST009"},
    # Retyped as a render prim, the prim is judged as one (where it lives too).
    "ST010": {"SE015", "ST003", "ST008", "ST009", "VA001"},
}


def _places(document: dict) -> set[tuple[str, str]]:
    return {(f["code"], f["path"] or "") for r in document["files"] for f in r["findings"]}


@pytest.mark.parametrize(("code", "fail"), list(_cases()))
def test_a_fix_makes_no_finding_of_another_rule(code: str, fail: Path, tmp_path: Path) -> None:
    """No fix leaves the stage with a problem it did not have: ST008's move left
    renderSettingsPrimPath on the old path, an ST005 error the fix made itself.
    Every rule lints the fixture before and after its rule's fixes."""
    path = copy_fixture(fail, tmp_path)
    every_rule = ["check", "--isolated", "--no-cache", "--jobs", "1", "--timeout", "0"]
    every_rule += ["--show-info", "--format", "json", str(path)]
    before = json.loads(CliRunner().invoke(cli, every_rule).stdout)
    run_fix(code, path)
    after = json.loads(CliRunner().invoke(cli, every_rule).stdout)
    new = {place[0] for place in _places(after) - _places(before)}
    assert new <= NEW_FINDINGS_EXPECTED.get(code, set()), sorted(new)
