"""Start-up of ``usdrender-lint check``: what it imports, and the entry point
lookup that lets it skip importlib.metadata (issue 6). Timing is measured by
``benchmarks/run.py --only startup``, never asserted here."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import click
import pytest
from cli_support import after_a_supervised_command

import usdrender_lint
from usdrender_lint import entrypoints
from usdrender_lint.formatters import available_formatters
from usdrender_lint.registry import build_registry

PASS_FILE = Path(__file__).parents[1] / "rules" / "CA001_camera_unset" / "pass_traps.usda"
GROUPS = ("usdrender_lint.rules", "usdrender_lint.formatters")
#: Modules a plain check (text report to a pipe, no config file) never needs.
NEVER_NEEDED = (
    "importlib.metadata",
    "email",
    "csv",
    "rich",
    "tomllib",
    "zipfile",
    "usdrender_lint.api.docs",
    "usdrender_lint.fixing",
    "usdrender_lint.running.roots",
    "usdrender_lint.engine.variants",
    "usdrender_lint.running.baseline",
    # check - (a text on standard input) and the documents it lints through.
    "usdrender_lint.running.standard_input",
    "usdrender_lint.running.documents",
    # The configuration digest (running/merge.py) is for the JSON report only;
    # writing stdout (atomic.write_all) needs no hash either.
    "usdrender_lint.running.merge",
    "hashlib",
    # Printed only for USDRENDER_LINT_DEBUG (debug.show).
    "traceback",
    # check --watch alone.
    "watchfiles",
    # Shell completion alone (cli/options.py's completers).
    "click.shell_completion",
    "usdrender_lint.running.watching",
    # The schema classes' bindings: rules name schemas as Tf.Type (api.schemas).
    "pxr.UsdRender",
    "pxr.UsdGeom",
    "pxr.UsdShade",
    "pxr.Sdr",
    # The other commands' modules (cli/__init__.py imports each on first use).
    "usdrender_lint.cli.clean",
    "usdrender_lint.cli.config_keys",
    "usdrender_lint.cli.explain",
    "usdrender_lint.cli.merge",
    "usdrender_lint.cli.plugin_path",
    "usdrender_lint.cli.rules",
    "usdrender_lint.cli.server",
    "usdrender_lint.cli.spec",
)
#: Modules only the worker pool needs (more than one job, or a --timeout).
POOL_ONLY = ("multiprocessing", "tempfile", "shutil")

IMPORTED_BY_CHECK = """
import sys
from usdrender_lint.cli import main
try:
    main(sys.argv[1:])
except SystemExit:
    pass
print(__import__("json").dumps(sorted(sys.modules)), file=sys.stderr)
"""


#: The formats this package registers (pyproject.toml's entry points).
OUR_FORMATS = {"full", "github", "gitlab", "html", "json", "junit", "sarif", "text"}


def _modules_after(*args: str) -> set[str]:
    proc = subprocess.run(
        [sys.executable, "-c", IMPORTED_BY_CHECK, "check", *args, str(PASS_FILE)],
        capture_output=True,
        text=True,
        check=True,
    )
    return set(json.loads(proc.stderr.splitlines()[-1]))


def _imported(modules: set[str], name: str) -> bool:
    return any(m == name or m.startswith(name + ".") for m in modules)


def test_check_in_one_process_imports_only_what_it_needs() -> None:
    modules = _modules_after("--isolated", "--jobs", "1", "--timeout", "0")
    assert "usdrender_lint.engine" in modules  # it did lint
    unexpected = [n for n in NEVER_NEEDED + POOL_ONLY if _imported(modules, n)]
    assert unexpected == []


def test_each_command_is_found_under_its_own_name() -> None:
    """The group imports a command's module when it is named: each name in its
    table is the command's own, and every command is listed."""
    from usdrender_lint.cli import cli

    names = list(cli.commands)
    assert names == sorted(names) and "check" in names
    assert [cli.commands[name].name for name in names] == names
    assert cli.get_command(click.Context(cli), "no-such-command") is None


COLLECTOR_AFTER_CHECK = """
import gc
import sys

from usdrender_lint.cli import main

try:
    main(sys.argv[1:])
except SystemExit:
    pass
from usdrender_lint.rules import RULES

walked = {id(o) for o in gc.get_objects()}  # frozen objects are in no generation
print(gc.isenabled(), any(id(rule) in walked for rule in RULES), file=sys.stderr)
"""


def test_the_collector_never_walks_the_rule_modules() -> None:
    """The rule modules are imported with the garbage collector paused and then
    frozen (with USD's objects); it runs again after them."""
    proc = subprocess.run(
        [sys.executable, "-c", COLLECTOR_AFTER_CHECK, "check", "--isolated", "--jobs", "1",
         "--timeout", "0", str(PASS_FILE)],
        capture_output=True,
        text=True,
        check=True,
    )  # fmt: skip
    enabled_after_check, rules_walked = proc.stderr.split()[-2:]
    assert (enabled_after_check, rules_walked) == ("True", "False")


def test_a_clean_file_needs_no_usda_line_finder() -> None:
    """layers.usda_text (its regular expressions and records) locates findings only."""
    clean = PASS_FILE.parents[3] / "examples" / "clean_shot" / "shot.usda"
    proc = subprocess.run(
        [
            sys.executable,
            "-c",
            IMPORTED_BY_CHECK,
            "check",
            "--isolated",
            "--no-cache",
            "--jobs",
            "1",
            "--timeout",
            "0",
            "--format",
            "json",
            str(clean),
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert json.loads(proc.stdout)["files"][0]["findings"] == []
    modules = set(json.loads(proc.stderr.splitlines()[-1]))
    assert "usdrender_lint.engine.locate" in modules
    assert "usdrender_lint.layers.usda_text" not in modules


def test_check_with_workers_imports_the_pool_and_nothing_else_heavy() -> None:
    other = PASS_FILE.parent.parent / "CA002_camera_multiple_targets" / "pass_traps.usda"
    modules = _modules_after("--isolated", str(other))  # two files, the default --timeout
    assert "multiprocessing" in modules
    assert [n for n in NEVER_NEEDED if _imported(modules, n)] == []


BEFORE_THE_FORK = """
import sys
before = set(sys.modules)
import usdrender_lint.__main__
print(*sorted(set(sys.modules) - before))
"""


def test_the_supervisor_imports_no_typing_before_it_forks() -> None:
    """__main__.py's imports are the supervisor's: it tears them down after the
    command (its child) has ended, so they hold no more than they need."""
    proc = subprocess.run(
        [sys.executable, "-c", BEFORE_THE_FORK], capture_output=True, text=True, check=True
    )
    imported = proc.stdout.split()
    assert "usdrender_lint.running.address_space" in imported
    assert [name for name in ("typing", "re", "contextlib") if name in imported] == []


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the supervisor is Linux's")
def test_a_supervised_check_imports_no_ctypes_and_no_pool() -> None:
    """Its child watches a pipe to end with the supervisor (running/supervisor.py)."""
    supervised, modules, _ = after_a_supervised_command(
        "sorted(sys.modules)", "check", "--isolated", str(PASS_FILE)
    )
    assert supervised  # the child's own modules
    assert "usdrender_lint.engine" in modules
    assert "ctypes" not in modules
    # One file under a time limit: the supervisor times the child, which lints
    # it in its own process with no pool (issue 17).
    assert [n for n in NEVER_NEEDED + POOL_ONLY if _imported(modules, n)] == []


def test_rule_docs_are_built_only_for_a_formatter_that_reads_them() -> None:
    modules = _modules_after("--isolated", "--jobs", "1", "--timeout", "0", "--format", "sarif")
    assert "usdrender_lint.api.docs" in modules  # SARIF describes the rules


def _pairs(found) -> list[tuple[str, str]]:
    return sorted((ep.name, ep.value) for ep in found)


@pytest.mark.parametrize("group", GROUPS)
def test_lookup_agrees_with_importlib_metadata(group: str) -> None:
    fast = entrypoints._single_registrant(group)
    assert fast is not None  # only usdrender-lint registers here: no importlib.metadata
    assert _pairs(fast) == _pairs(metadata.entry_points(group=group))
    assert [ep.load() for ep in sorted(fast, key=lambda e: e.name)] == [
        ep.load() for ep in sorted(metadata.entry_points(group=group), key=lambda e: e.name)
    ]


def _dist(site: Path, folder: str, entry_points: str | None) -> None:
    info = site / folder
    info.mkdir(parents=True)
    name = folder.partition("-")[0]
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 9\n")
    if entry_points is not None:
        (info / "entry_points.txt").write_text(entry_points)


def test_a_plugin_in_the_group_is_found_through_importlib_metadata(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _dist(tmp_path, "acme_fmt-1.dist-info", "[usdrender_lint.formatters]\nacme = json:dumps\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert entrypoints._single_registrant("usdrender_lint.formatters") is None
    assert available_formatters()["acme"].value == "json:dumps"
    assert set(available_formatters()) == {"acme", *OUR_FORMATS}


def test_a_shadowing_distribution_hides_ours_as_in_importlib_metadata(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # importlib.metadata keeps the first distribution of a name on sys.path.
    _dist(tmp_path, "usdrender_lint-9.dist-info", "[console_scripts]\nx = json:dumps\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert metadata.entry_points(group="usdrender_lint.formatters") == ()
    assert entrypoints.entry_points("usdrender_lint.formatters") == ()


def test_a_malformed_file_anywhere_fails_as_in_importlib_metadata(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _dist(tmp_path, "other-1.dist-info", "[console_scripts]\nno equals sign\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(TypeError):
        metadata.entry_points(group="usdrender_lint.rules")
    with pytest.raises(TypeError):
        entrypoints.entry_points("usdrender_lint.rules")


def test_nothing_is_cached_between_lookups(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(tmp_path))
    assert set(available_formatters()) == OUR_FORMATS
    _dist(tmp_path, "late-1.dist-info", "[usdrender_lint.formatters]\nlate = json:dumps\n")
    assert "late" in available_formatters()


def test_builtin_rules_load_from_the_light_entry_point() -> None:
    registry = build_registry()
    assert registry.plugins() == {"builtin"}
    assert len(registry.rules) == len(build_registry(metadata.entry_points(group=GROUPS[0])).rules)


def test_version_is_the_installed_distributions() -> None:
    assert usdrender_lint.__version__ == metadata.version("usdrender-lint")


GC_AROUND_IMPORTS = """
import gc, sys
import usdrender_lint.cli as cli
from usdrender_lint.cli.loading import import_engine
assert not any(m.startswith("pxr") for m in sys.modules), "the cli module imports USD"
if sys.argv[1] == "off":
    gc.disable()
import_engine()
print(gc.isenabled(), gc.get_freeze_count() > 0, "pxr.Usd" in sys.modules)
"""


@pytest.mark.parametrize(("before", "after"), [("on", "True"), ("off", "False")])
def test_usd_is_imported_with_collection_paused_then_frozen(before: str, after: str) -> None:
    proc = subprocess.run(
        [sys.executable, "-c", GC_AROUND_IMPORTS, before],
        capture_output=True,
        text=True,
        check=True,
    )
    assert proc.stdout.split() == [after, "True", "True"]


VERSION_AND_HELP = """
import sys
import usdrender_lint.cli as cli
try:
    cli.main([sys.argv[1]])
except SystemExit:
    pass
print("pxr.Usd" in sys.modules, file=sys.stderr)
"""


@pytest.mark.parametrize("flag", ["--version", "--help"])
def test_version_and_help_do_not_import_usd(flag: str) -> None:
    proc = subprocess.run(
        [sys.executable, "-c", VERSION_AND_HELP, flag], capture_output=True, text=True, check=True
    )
    assert proc.stderr.split() == ["False"]
    assert "usdrender-lint" in proc.stdout


def test_format_names_are_looked_up_when_click_needs_them(monkeypatch) -> None:
    """Not when a command is defined: each lookup reads every distribution's
    entry points, and check would pay for merge's --format too."""
    from usdrender_lint import formatters
    from usdrender_lint.cli.options import FormatChoice

    lookups: list[str] = []

    def available() -> dict[str, str]:
        lookups.append("looked up")
        return {"text": "t", "json": "j"}

    monkeypatch.setattr(formatters, "available_formatters", available)
    choice = FormatChoice()
    assert lookups == []
    with click.Context(click.Command("check")):  # once per command line run
        assert choice.convert("JSON", None, None) == "json"
        assert choice.choices == ("json", "text")
    assert lookups == ["looked up"]


@pytest.mark.parametrize("output_format", ["text", "json"])
def test_a_check_looks_the_formatters_up_once(
    output_format: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """--format is checked against the registered formatters, and the report
    written by one of those same ones: every distribution's entry points are
    read once, not again to load it."""
    from cli_support import invoke_in

    from usdrender_lint import formatters

    lookups: list[str] = []

    def counted(group: str):
        lookups.append(group)
        return entrypoints.entry_points(group)

    monkeypatch.setattr(formatters, "entry_points", counted)
    args = ["check", "--isolated", "--no-cache", "--jobs", "1", "--timeout", "0"]
    for run in (1, 2):  # each run in this process looks them up anew, once
        result = invoke_in(tmp_path, *args, "--format", output_format, str(PASS_FILE))
        assert result.exit_code == 1, result.output  # the file's ST004 warning: a report
        assert lookups == [formatters.ENTRY_POINT_GROUP] * run


def test_a_check_reads_the_entry_points_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The formatters (--format) and the rule plugins come from one reading of
    the installed distributions' entry points: each reading lists every folder
    of sys.path and reads every entry_points.txt (about 5M instructions here)."""
    from cli_support import invoke_in

    readings: list[str] = []
    read = entrypoints._declarations

    def counted():
        readings.append("read")
        return read()

    monkeypatch.setattr(entrypoints, "_declarations", counted)
    args = ["check", "--isolated", "--no-cache", "--jobs", "1", "--timeout", "0"]
    for run in (1, 2):  # each command line run reads them anew, once
        result = invoke_in(tmp_path, *args, str(PASS_FILE))
        assert result.exit_code == 1, result.output  # the file's ST004 warning: a report
        assert readings == ["read"] * run


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS as Linux keeps it")
@pytest.mark.parametrize("mib", [30, 60, 300])
@pytest.mark.parametrize("args", [("check", str(PASS_FILE)), ("rules",)])
def test_a_tiny_memory_limit_is_one_line_and_exit_2(mib: int, args: tuple[str, ...]) -> None:
    """Under ``ulimit -v`` too small to load USD the command says so in one line
    (exit 2), instead of a traceback (30, 60 MiB) or USD's own tracebacks and a
    crash (300 MiB)."""
    import resource

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (mib * 2**20, resource.RLIM_INFINITY))

    run = subprocess.run(
        [sys.executable, "-m", "usdrender_lint", *args],
        capture_output=True,
        text=True,
        timeout=120,
        preexec_fn=limit,
    )
    assert (run.returncode, run.stdout) == (2, ""), run.stderr
    assert run.stderr.splitlines() == [
        f"usdrender-lint: error: out of memory: the address-space limit (ulimit -v) is {mib} MiB, "
        "too small to load USD (it maps about 600 MiB as it loads): raise it"
    ]


def test_a_memory_error_past_the_command_s_own_handlers_is_one_line(
    monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    """Under ``ulimit -v`` about 1 GiB, USD loads and then runs out: the command's
    handlers, which allocate, could fail in turn, and a traceback reached the user."""
    import usdrender_lint.__main__ as entry
    import usdrender_lint.cli

    def no_memory(supervision: object = None) -> None:
        raise MemoryError

    monkeypatch.setattr(usdrender_lint.cli, "main", no_memory)
    monkeypatch.setattr(sys, "argv", ["usdrender-lint", "rules"])
    with pytest.raises(SystemExit) as exited:
        entry.main()
    assert exited.value.code == 2
    assert capfd.readouterr().err.splitlines() == [
        "usdrender-lint: error: out of memory: raise the memory limit (ulimit -v)"
    ]


@pytest.mark.parametrize("fails", ["ENOMEM", "ENOSPC"])
def test_an_os_error_while_reporting_is_one_line_without_importing_traceback(
    fails: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Seen under ``ulimit -v`` 1.1 GiB: listing the formatters' entry points
    failed with ENOMEM (an OSError, taken for a write error), and the handler's
    ``import traceback`` then failed for want of memory: two tracebacks. ENOMEM
    is now the out-of-memory line, and no handler imports a module."""
    import errno

    from usdrender_lint import cli, formatters

    def listing_fails() -> dict:
        raise OSError(getattr(errno, fails), os.strerror(getattr(errno, fails)))

    monkeypatch.setattr(formatters, "available_formatters", listing_fails)
    monkeypatch.setitem(sys.modules, "traceback", None)  # its import fails, as it did
    monkeypatch.setattr(
        "usdrender_lint.running.address_space.address_space_limit", lambda: 1100 << 20
    )
    with pytest.raises(SystemExit) as exited:
        cli.main(["check", "--no-cache", "--timeout", "0", str(PASS_FILE)])
    assert exited.value.code == 2
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 1, lines
    if fails == "ENOMEM":
        assert lines == [
            "usdrender-lint: error: out of memory: the address-space limit (ulimit -v) is "
            "1100 MiB: raise it"
        ]
    else:
        assert lines[0].startswith("usdrender-lint: internal error: OSError: ")
