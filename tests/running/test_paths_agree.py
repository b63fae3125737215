"""The differential test: every real file (``../shared/corpus``) and every
fixture of the suite gets the same answer on every path it can be linted by.

The paths: the result cache cold and warm, ``--no-cache --jobs 2`` (the pool),
``--jobs 1 --timeout 0`` (in-process), a lone file (the supervised child's
path) and the same file among others, its text on standard input (``check -
--stdin-filename``, every text layer), three ``--shard K/3`` runs joined by
``merge``, the Python API's ``lint_file`` and ``lint_stage`` (on the stage
USD opens from the file, and on one a host opens with its own session layer,
as the Asset Validator does), and the
UsdValidation plugin (as far as its errors map: code, site path, layer,
message and severity; its errors carry no profile). A file that one path lints
and another cannot is a difference too. And a file edited between two runs
(the root, a sublayer's sublayer or a referenced layer; its size kept, its
time new or set back) gets the fresh answer from the cached command and from
a host process that linted it before (the Python API, the UsdValidation
validators; the Asset Validator's in tests/assetvalidator).

Cheap by design: one process per path over every file (about 700 of them), not
one per file; the lone-file path forks one child per file from a process that
imported the engine once (every real file, every eighth fixture), and three
files take the whole installed command.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from collections.abc import Iterable
from pathlib import Path

import pytest
from conftest import REPO, SHARED
from pxr import Sdf, Tf, Usd

from usdrender_lint import lint_file, lint_stage
from usdrender_lint.formatters import FormatOptions
from usdrender_lint.formatters.json import report_to_dict
from usdrender_lint.usdplugin import plugin_dir

pytestmark = pytest.mark.heavy(seconds=155)

USD_SUFFIXES = {".usd", ".usda", ".usdc", ".usdz"}
#: What a finding is, for the comparison.
FIELDS = ("code", "path", "layer", "line", "message", "severity", "profile", "profile_reason")
#: The plugin's errors carry no line, nor the profile a finding was judged under.
PLUGIN_FIELDS = ("code", "path", "layer", "message", "severity")


def _usd_files(folder: Path) -> list[Path]:
    return sorted(p for p in folder.rglob("*") if p.suffix.lower() in USD_SUFFIXES and p.is_file())


def _targets() -> list[str]:
    files = _usd_files(REPO / "tests")
    corpus = SHARED / "corpus" / "files"
    if corpus.is_dir():
        files += _usd_files(corpus)
    return [str(p.resolve()) for p in files]


TARGETS = _targets()
#: Every path runs from a folder above no file (no checkout is ever under
#: /proc), so that each shows the same absolute paths.
ELSEWHERE = "/proc"
CORPUS_PRESENT = (SHARED / "corpus" / "files").is_dir()


def _answers(document: dict, fields: Iterable[str] = FIELDS) -> dict[str, tuple]:
    """Per file: its status, its error line, and its findings (sorted)."""
    fields = tuple(fields)
    out = {}
    for entry in document["files"]:
        # repr: a missing line sorts beside a number.
        findings = sorted(tuple(repr(f.get(k)) for k in fields) for f in entry["findings"])
        out[entry["file"]] = (entry["status"], entry.get("error"), tuple(findings))
    return out


def _env(**extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("USDRENDER_LINT_")}
    env.update(extra)
    return env


def _check(*args: str, env: dict[str, str] | None = None, files: list[str] = TARGETS) -> dict:
    """One ``check`` process over ``files``: its JSON report."""
    done = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "--format", "json"]
        + ["--fail-on", "never", "--show-info", *args, *files],
        capture_output=True,
        env=env or _env(),
        timeout=600,
        cwd=ELSEWHERE,
    )
    assert "Traceback" not in done.stderr.decode(errors="replace"), done.stderr[-3000:]
    assert done.returncode in (0, 2), done.stderr[-3000:]
    return json.loads(done.stdout)


#: The supervised child's path, one forked child per file: the command runs as
#: it does in the child ``supervisor.supervise`` leaves (a lone file linted in
#: that process), minus the interpreter's start-up. With ``stdin``, as an
#: editor's hook runs it: the file's text on standard input (``check -
#: --stdin-filename``).
_LONE = """
import os, sys
from usdrender_lint import cli, lint_file
from usdrender_lint.running import supervisor

out, how, files = sys.argv[1], sys.argv[2], sys.argv[3:]
lint_file(files[0])  # USD, the engine, the rules and their first-use costs: once, here
# The modules the route imports on its first use, imported here once too, not
# again in every child: the command's and its report's, and for a text the
# documents' (with pxr.UsdUtils), which a file named does not import.
import usdrender_lint.cli.check, usdrender_lint.formatters.json
if how == "stdin":
    import usdrender_lint.running.documents
for index, path in enumerate(files):
    child = os.fork()
    if child == 0:
        code = 3
        try:
            report = os.open(f"{out}/{index}.json", os.O_WRONLY | os.O_CREAT, 0o644)
            os.dup2(report, 1)
            named = [path]
            if how == "stdin":
                os.dup2(os.open(path, os.O_RDONLY), 0)
                named = ["-", "--stdin-filename", path]
            cli.main(["check", "--isolated", "--no-cache", "--format", "json", "--show-info",
                      "--fail-on", "never", *named], supervision=supervisor.Supervision())
        except SystemExit as done:
            code = done.code if isinstance(done.code, int) else 3
        finally:
            os._exit(code)
    _, status = os.waitpid(child, 0)
    if os.waitstatus_to_exitcode(status) not in (0, 2):
        print(f"{path}: exit {os.waitstatus_to_exitcode(status)}", file=sys.stderr)
        sys.exit(1)
"""


def _forked(how: str, folder: Path, files: list[str]) -> dict:
    """``_LONE`` over ``files``, each named (``how`` "file") or on standard input ("stdin")."""
    done = subprocess.run(
        [sys.executable, "-c", _LONE, str(folder), how, *files],
        capture_output=True,
        env=_env(),
        timeout=600,
        cwd=ELSEWHERE,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    found = []
    for index in range(len(files)):
        found += json.loads((folder / f"{index}.json").read_text())["files"]
    return {"files": found}


def _is_text(path: str) -> bool:
    """What ``check -`` takes: a layer held as text (not a crate, not a package)."""
    with open(path, "rb") as file:
        return file.read(8) not in (b"PXR-USDC",) and not path.lower().endswith(".usdz")


def _api() -> dict:
    files = []
    for path in TARGETS:
        report = lint_file(path)
        files += report_to_dict(report, FormatOptions(show_info=True))["files"]
    return {"files": files}


def _api_stages(session: str | None = None) -> dict:
    """``lint_stage`` on every file USD opens (a file it refuses has no stage to
    hand over); with ``session``, each stage opened with an anonymous session
    layer of that name, as a host opens it (the Asset Validator's is
    "AssetValidator")."""
    files = []
    for path in TARGETS:
        try:
            if session is None:
                stage = Usd.Stage.Open(path)
            else:
                root, own = Sdf.Layer.FindOrOpen(path), Sdf.Layer.CreateAnonymous(session)
                stage = Usd.Stage.Open(root, own)
        except Tf.ErrorException:
            continue
        if stage is None:
            continue
        report = lint_stage(stage, file=path)
        files += report_to_dict(report, FormatOptions(show_info=True))["files"]
    return {"files": files}


#: The validators through OpenUSD's registry, on every file USD opens.
_PLUGIN = """
import json, sys
from pxr import Sdf, Tf, Usd, UsdValidation

registry = UsdValidation.ValidationRegistry()
validators = [
    registry.GetOrLoadValidatorByName(m.name)
    for m in registry.GetValidatorMetadataForKeyword("usdRenderLint")
]
context = UsdValidation.ValidationContext(validators)
severity = {"Error": "error", "Warn": "warning", "Info": "info"}

def site_path(site):
    if site.IsProperty():
        return str(site.GetProperty().GetPath())
    if site.IsPrim() and not site.GetPrim().IsPseudoRoot():
        return str(site.GetPrim().GetPath())
    return None

def abstract_typed(stage, where):
    prim = stage.GetPrimAtPath(Sdf.Path(where).GetPrimPath()) if where else None
    if not prim:
        return False
    registered = Usd.SchemaRegistry.GetTypeFromName(prim.GetTypeName())
    return not registered.isUnknown and prim.GetPrimTypeInfo().GetSchemaType().isUnknown

files = []
for path in sys.argv[1:]:
    try:
        stage = Usd.Stage.Open(path)
    except Tf.ErrorException:
        continue  # no stage to validate (the CLI's ST001)
    findings = []
    for error in context.Validate(stage):
        site = error.GetSites()[0]
        layer = site.GetLayer()
        findings.append({
            "code": error.GetName(),
            "path": site_path(site),
            "layer": layer.realPath or layer.identifier if layer else None,
            "message": error.GetMessage(),
            "severity": severity[str(error.GetType()).rsplit(".", 1)[-1]],
        })
    # USD gives a prim typed with an abstract schema (def RenderSettingsBase) no
    # schema type, so UsdValidation never hands it to a validator: those
    # prims' paths, for the comparison to set findings on them aside.
    untyped = sorted(
        {str(p.GetPath()) for p in stage.Traverse() if abstract_typed(stage, str(p.GetPath()))}
    )
    files.append({"file": path, "status": "linted", "error": None, "findings": findings,
                  "untyped": untyped})
print(json.dumps({"files": files}))
"""


def _plugin() -> dict:
    done = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(_PLUGIN), *TARGETS],
        capture_output=True,
        env=_env(PXR_PLUGINPATH_NAME=str(plugin_dir())),
        timeout=600,
        cwd=ELSEWHERE,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.decode().strip().splitlines()[-1])


def _differences(reference: dict[str, tuple], other: dict[str, tuple]) -> list[str]:
    """One line per file whose answer differs (a file one side lacks included)."""
    lines = []
    for file in sorted(set(reference) | set(other)):
        mine, theirs = reference.get(file), other.get(file)
        if mine == theirs:
            continue
        if mine is None or theirs is None:
            lines.append(f"{file}: linted on one path only")
            continue
        status = f"{mine[0]} / {theirs[0]}: {mine[1] or ''} / {theirs[1] or ''}"
        only_ref = sorted(set(mine[2]) - set(theirs[2]))[:3]
        only_other = sorted(set(theirs[2]) - set(mine[2]))[:3]
        lines.append(f"{file}: {status}; only in reference {only_ref}; only here {only_other}")
    return lines


@pytest.fixture(scope="module")
def reference_report() -> dict:
    """``--no-cache --jobs 2``: the pool, the files among others; its JSON report."""
    return _check("--no-cache", "--jobs", "2")


@pytest.fixture(scope="module")
def reference(reference_report: dict) -> dict[str, tuple]:
    return _answers(reference_report)


def test_there_is_real_content_to_compare() -> None:
    assert len(TARGETS) > 400  # the fixtures alone
    if CORPUS_PRESENT:
        corpus = [t for t in TARGETS if "/corpus/files/" in t]
        assert len(corpus) > 190, len(corpus)


def test_every_file_is_linted(reference: dict[str, tuple]) -> None:
    """Every file gives findings or a clean ST001: none is a tool error."""
    assert set(reference) == set(TARGETS)
    errored = [f"{file}: {why}" for file, (done, why, _) in reference.items() if done != "linted"]
    assert errored == []


def test_the_cache_cold_and_warm_and_the_in_process_path_agree(
    reference: dict[str, tuple], tmp_path: Path
) -> None:
    cache = ["--cache-dir", str(tmp_path / "cache")]
    cold = _answers(_check(*cache))
    warm = _answers(_check(*cache))
    assert any((tmp_path / "cache").rglob("*")), "the cold run stored nothing"
    in_process = _answers(_check("--no-cache", "--jobs", "1", "--timeout", "0"))
    for name, answers in (("cold", cold), ("warm", warm), ("--jobs 1 --timeout 0", in_process)):
        assert _differences(reference, answers) == [], name


def test_a_lone_file_gets_its_answer_among_others(
    reference: dict[str, tuple], tmp_path: Path
) -> None:
    """Every real file, and every eighth fixture (each child costs about 25 ms
    of CPU: the whole command but the interpreter's start-up)."""
    fixtures = [t for t in TARGETS if "/corpus/files/" not in t]
    files = [t for t in TARGETS if "/corpus/files/" in t] + fixtures[::8]
    alone = _answers(_forked("file", tmp_path, files))
    assert set(alone) == set(files)
    assert _differences({f: reference[f] for f in files}, alone) == []


def test_a_text_on_standard_input(reference: dict[str, tuple], tmp_path: Path) -> None:
    """Every real text layer, and every fourth fixture that is text."""
    fixtures = [t for t in TARGETS if "/corpus/files/" not in t]
    files = [t for t in TARGETS if "/corpus/files/" in t] + fixtures[::4]
    files = [f for f in files if _is_text(f)]
    assert len(files) > 100
    piped = _answers(_forked("stdin", tmp_path, files))
    assert set(piped) == set(files)
    assert _differences({f: reference[f] for f in files}, piped) == []


def test_shards_joined_by_merge(reference: dict[str, tuple], tmp_path: Path) -> None:
    reports = []
    for index in (1, 2, 3):
        report = tmp_path / f"shard{index}.json"
        report.write_text(json.dumps(_check("--no-cache", "--shard", f"{index}/3")))
        reports.append(str(report))
    merged = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", "merge", "--format", "json", "--show-info"]
        + ["--fail-on", "never", *reports],
        capture_output=True,
        env=_env(),
        timeout=600,
        cwd=ELSEWHERE,
    )
    assert merged.returncode in (0, 2), merged.stderr[-3000:]
    assert _differences(reference, _answers(json.loads(merged.stdout))) == []


def test_variants_only_add_to_the_answer(reference: dict[str, tuple]) -> None:
    """``--variants`` lints the authored selection too: every finding of the
    plain check is among its findings (but UL001, an unused suppression, which
    another combination may use), and every file has the same status."""
    varied = _answers(_check("--no-cache", "--variants"))
    assert set(varied) == set(reference)
    lost = []
    for file, (status, error, findings) in reference.items():
        if varied[file][:2] != (status, error):
            lost.append(f"{file}: {varied[file][:2]} against {(status, error)}")
            continue
        missing = [f for f in set(findings) - set(varied[file][2]) if f[0] != repr("UL001")]
        if missing:
            lost.append(f"{file}: only without --variants {sorted(missing)[:3]}")
    assert lost == []
    assert any(varied[f] != reference[f] for f in reference), "no file has variants to lint"


def test_the_installed_command_on_a_lone_file(reference: dict[str, tuple]) -> None:
    """The real supervisor, its child and the interpreter's start-up, on a few
    files (the harness above covers every file)."""
    sample = TARGETS[:: max(1, len(TARGETS) // 3)][:3]
    for path in sample:
        alone = _answers(_check("--no-cache", files=[path]))
        assert alone == {path: reference[path]}


def test_the_python_api(reference: dict[str, tuple], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ELSEWHERE)
    assert _differences(reference, _answers(_api())) == []


@pytest.mark.parametrize("session", [None, "AssetValidator"])
def test_the_python_api_on_open_stages(
    reference: dict[str, tuple], monkeypatch: pytest.MonkeyPatch, session: str | None
) -> None:
    monkeypatch.chdir(ELSEWHERE)
    staged = _answers(_api_stages(session))
    # USD refuses a file that check reports with ST001 alone: no stage to hand over.
    refused = {
        file: answer
        for file, answer in reference.items()
        if file not in staged and {f[0] for f in answer[2]} == {repr("ST001")}
    }
    assert len(staged) > len(TARGETS) * 0.8
    assert _differences({f: a for f, a in reference.items() if f not in refused}, staged) == []


def test_the_usdvalidation_plugin_as_far_as_its_errors_map(reference_report: dict) -> None:
    # The command's own report (the reference's run, not a second one alike).
    checked = reference_report
    plugin = _plugin()
    validated = {entry["file"]: entry for entry in plugin["files"]}
    cli, mapped = {}, {}
    for entry in checked["files"]:
        file = entry["file"]
        if file not in validated:
            # USD refuses the file: the CLI says so with ST001 alone.
            assert {f["code"] for f in entry["findings"]} == {"ST001"}, file
            continue
        untyped = set(validated[file]["untyped"])

        def kept(findings: list[dict], untyped: set[str] = untyped) -> list[dict]:
            # Prims of an abstract type are set aside on both sides (see _PLUGIN).
            return [f for f in findings if (f["path"] or "").split(".")[0] not in untyped]

        cli[file] = {**entry, "findings": kept(entry["findings"])}
        mapped[file] = {**validated[file], "findings": kept(validated[file]["findings"])}
    assert len(cli) > len(TARGETS) * 0.8
    expected = _answers({"files": list(cli.values())}, PLUGIN_FIELDS)
    got = _answers({"files": list(mapped.values())}, PLUGIN_FIELDS)
    assert _differences(expected, got) == []


# -- a file edited between two runs ------------------------------------------------

#: A shot whose lint reads every kind of layer: the root, a sublayer's
#: sublayer, a referenced camera. Each edit below keeps its file's size.
_SHOT = {
    "shot.usda": textwrap.dedent(
        """\
        #usda 1.0
        (
            subLayers = [@lighting.usda@]
            renderSettingsPrimPath = "/Render/Settings"
        )
        def "cam" (references = @cam.usda@</Cam>)
        {
        }
        def Scope "Render"
        {
            def RenderSettings "Settings"
            {
                rel camera = </cam>
                rel products = [</Render/Beauty>]
                uniform int2 resolution = (1920, 1080)
            }
            def RenderProduct "Beauty"
            {
                token productName = "beauty.####.exr"
                rel orderedVars = [</Render/Color>]
                uniform float4 dataWindowNDC = (0.25, 0.25, 0.75, 0.75)
            }
        }
        """
    ),
    "lighting.usda": '#usda 1.0\n(\n    subLayers = [@vars.usda@]\n)\nover "Render"\n{\n'
    '    over "Beauty"\n    {\n        uniform float pixelAspectRatio = 1.0\n    }\n}\n',
    "vars.usda": '#usda 1.0\ndef Scope "Render"\n{\n    def RenderVar "Color"\n    {\n'
    '        uniform string sourceName = "Ci"\n        uniform token sourceType = "lpe"\n'
    "    }\n}\n",
    "cam.usda": '#usda 1.0\ndef Camera "Cam"\n{\n    float horizontalAperture = 36\n'
    "    float verticalAperture = 20.25\n}\n",
}
#: (file, text, the same number of bytes in its place, whether the file's
#: modification time is set back after the edit).
_EDITS = (
    ("shot.usda", "(0.25, 0.25, 0.75, 0.75)", "(0.75, 0.25, 0.25, 0.75)", True),
    ("lighting.usda", "pixelAspectRatio = 1.0", "pixelAspectRatio = 0.0", False),
    ("vars.usda", 'sourceType = "lpe"', 'sourceType = "xyz"', True),
    ("cam.usda", 'def Camera "Cam"', 'def Xform  "Cam"', False),
)

#: In one process, as a host application lints: each shot once, then again
#: after its edit, by the Python API and by the UsdValidation validators (on a
#: stage opened anew, the first one closed).
_HOSTS = """
import gc, json, os, sys
from pxr import Usd, UsdValidation
from usdrender_lint import lint_file

registry = UsdValidation.ValidationRegistry()
context = UsdValidation.ValidationContext([
    registry.GetOrLoadValidatorByName(m.name)
    for m in registry.GetValidatorMetadataForKeyword("usdRenderLint")
])

def site_path(site):
    if site.IsProperty():
        return str(site.GetProperty().GetPath())
    if site.IsPrim() and not site.GetPrim().IsPseudoRoot():
        return str(site.GetPrim().GetPath())
    return None

def api(path):
    return sorted([f.code, f.location.path, f.message] for f in lint_file(path).findings)

def validation(path):
    stage = Usd.Stage.Open(path)
    errors = context.Validate(stage)
    found = sorted([e.GetName(), site_path(e.GetSites()[0]), e.GetMessage()] for e in errors)
    del stage, errors
    gc.collect()  # the host is done with the stage
    return found

out = {}
for edit in json.loads(sys.argv[1]):
    shot = os.path.join(edit["folder"], "shot.usda")
    before = {"api": api(shot), "usdvalidation": validation(shot)}
    path = os.path.join(edit["folder"], edit["file"])
    times = os.stat(path)
    with open(path, encoding="utf-8") as file:
        text = file.read()
    with open(path, "w", encoding="utf-8") as file:
        file.write(text.replace(edit["old"], edit["new"]))
    if edit["restore"]:
        os.utime(path, ns=(times.st_atime_ns, times.st_mtime_ns))
    out[shot] = {"before": before, "after": {"api": api(shot), "usdvalidation": validation(shot)}}
print(json.dumps(out))
"""


def _shots(root: Path) -> list[dict]:
    """One copy of the shot per edit (not made yet), its layers' times in the past."""
    edits = []
    for index, (file, old, new, restore) in enumerate(_EDITS):
        folder = root / f"shot{index}"
        folder.mkdir()
        for name, text in _SHOT.items():
            (folder / name).write_text(text)
            os.utime(folder / name, (1_700_000_000, 1_700_000_000))
        assert old in _SHOT[file] and len(old) == len(new)
        edits.append(
            {"folder": str(folder), "file": file, "old": old, "new": new, "restore": restore}
        )
    return edits


def test_a_file_edited_between_two_runs_gets_the_fresh_answer_on_every_path(
    tmp_path: Path,
) -> None:
    """The root layer, a sublayer's sublayer or a referenced layer edited
    between two runs (its size kept; its modification time new or set back):
    the second run of the cached command and of a host process that linted the
    file before (the Python API, the UsdValidation validators) gives the answer
    of a fresh ``check --no-cache``, each edit changing that answer."""
    edits = _shots(tmp_path)
    shots = [str(Path(e["folder"], "shot.usda")) for e in edits]
    cache = ["--cache-dir", str(tmp_path / "cache")]
    first = _answers(_check(*cache, files=shots))
    done = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(_HOSTS), json.dumps(edits)],
        capture_output=True,
        env=_env(PXR_PLUGINPATH_NAME=str(plugin_dir())),
        timeout=600,
        cwd=ELSEWHERE,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    hosts = json.loads(done.stdout.decode().strip().splitlines()[-1])
    fresh = _check("--no-cache", files=shots)
    assert _differences(_answers(fresh), _answers(_check(*cache, files=shots))) == []
    stale = []
    for entry in fresh["files"]:
        expected = sorted([f["code"], f["path"], f["message"]] for f in entry["findings"])
        assert first[entry["file"]] != _answers({"files": [entry]})[entry["file"]]
        for route, found in hosts[entry["file"]]["after"].items():
            if found != expected:
                stale.append(f"{entry['file']} by {route}: {found} against {expected}")
    assert stale == []
