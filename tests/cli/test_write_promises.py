"""What the command writes, it writes onto nothing it must not:

- never a report, baseline or picture onto a file the same run reads (one
  line, exit 2, the file untouched);
- ``--fix`` undoes its rename when the file changed while the fix was written
  (an edit through the old file would be lost with it) and says so, exit 2;
- file names of 241 bytes and more can be fixed and written (the temporary
  file's name stays within 255 bytes);
- ``--fix-to /dev/null`` and ``--version > /dev/full`` are one-line errors;
- ``USDRENDER_LINT_DEBUG=1`` prints the traceback of an internal error, in
  this process, in the supervised child and in a worker process.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from usdrender_lint import atomic
from usdrender_lint.cli import cli
from usdrender_lint.layers import writing
from usdrender_lint.running.outputs import OutputOnInput, refuse_inputs

pytestmark = pytest.mark.heavy(seconds=30)

REPO = Path(__file__).resolve().parents[2]
SHOT = (REPO / "examples" / "broken_shot" / "shot.usda").read_text(encoding="utf-8")


def command(*args: str) -> list[str]:
    return [sys.executable, "-m", "usdrender_lint", *args]


def run(*args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        command(*args), capture_output=True, text=True, timeout=120, env=env or os.environ.copy()
    )


@pytest.fixture
def shot(tmp_path: Path) -> Path:
    path = tmp_path / "shot.usda"
    path.write_text(SHOT, encoding="utf-8")
    return path


# -- never onto an input ---------------------------------------------------------------


@pytest.mark.parametrize(
    ("args", "what"),
    [
        (["check", "--isolated", "--format", "json", "--output", "{}"], "the report"),
        (["check", "--isolated", "--write-baseline", "{}"], "the baseline"),
        (["spec", "--isolated", "--format", "json", "--output", "{}"], "the specification"),
    ],
)
@pytest.mark.parametrize("by_link", [False, True])
def test_no_output_onto_an_input(shot: Path, args: list[str], what: str, by_link: bool) -> None:
    target = shot
    if by_link:
        target = shot.parent / "report.json"
        target.symlink_to(shot.name)
    argv = [str(target) if a == "{}" else a for a in args]
    result = run(*argv, str(shot))
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1, result.stderr
    assert f"refusing to write {what} onto it" in result.stderr
    assert shot.read_text(encoding="utf-8") == SHOT


@pytest.mark.parametrize(
    "args",
    [
        ["check", "--isolated", "--format", "json", "--output", "{}"],
        ["check", "--isolated", "--write-baseline", "{}"],
        ["spec", "--isolated", "--format", "json", "--output", "{}"],
        ["merge", "--format", "json", "--output", "{}"],
    ],
)
def test_an_output_in_folders_that_do_not_exist_yet_creates_them(
    shot: Path, tmp_path: Path, args: list[str]
) -> None:
    """As ruff's --output-file: a CI job's ``--output reports/x.sarif`` linted
    every file, then failed (exit 2) for want of reports/, after --fix had
    written its fixes."""
    target = tmp_path / "reports" / "new" / "out.json"
    if args[0] == "merge":
        report = tmp_path / "report.json"
        run("check", "--isolated", "--format", "json", "--output", str(report), str(shot))
        inputs = [str(report)]
    else:
        inputs = [str(shot)]
    result = CliRunner().invoke(cli, [a.replace("{}", str(target)) for a in args] + inputs)
    assert result.exit_code in (0, 1), result.output
    assert json.loads(target.read_text(encoding="utf-8"))


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["check", "--isolated", "--output", "{}"], "cannot write the report"),
        (["check", "--isolated", "--write-baseline", "{}"], "cannot write baseline"),
        (["spec", "--isolated", "--output", "{}"], "the file is read-only"),
    ],
)
def test_a_read_only_output_file_is_left_alone(
    shot: Path, tmp_path: Path, args: list[str], message: str
) -> None:
    """The rename replaced a read-only report or baseline, which the shell's >
    (and --fix, for a layer) leaves alone."""
    target = tmp_path / "kept.json"
    target.write_text("protected\n")
    target.chmod(0o444)
    result = CliRunner().invoke(cli, [a.replace("{}", str(target)) for a in args] + [str(shot)])
    assert result.exit_code == 2, result.output
    assert message in result.stderr and "read-only" in result.stderr
    assert target.read_text() == "protected\n"


def test_no_report_onto_a_layer_the_stage_composes(tmp_path: Path) -> None:
    (tmp_path / "layer.usda").write_text("#usda 1.0\n")
    root = tmp_path / "root.usda"
    root.write_text("#usda 1.0\n(\n    subLayers = [@./layer.usda@]\n)\n")
    result = CliRunner().invoke(
        cli, ["check", "--isolated", "--output", str(tmp_path / "layer.usda"), str(root)]
    )
    assert result.exit_code == 2
    assert "is a USD layer; refusing to write the report onto it" in result.output
    assert (tmp_path / "layer.usda").read_text() == "#usda 1.0\n"


def test_a_picture_onto_an_input_is_refused(tmp_path: Path) -> None:
    picture = tmp_path / "beauty.svg"
    picture.write_text("<svg/>")
    with pytest.raises(OutputOnInput, match="beauty.svg: is an input of this run"):
        refuse_inputs([(str(picture), "a picture")], [str(picture)])
    refuse_inputs([(str(tmp_path / "new.svg"), "a picture")], [str(picture)])  # not there yet


# -- --fix's write window ------------------------------------------------------------


def test_an_edit_through_the_old_file_after_the_rename_is_kept(
    shot: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A writer that opened the file before the rename appends after it: the
    fix is undone, the edit kept, the run says so and exits 2."""
    real = writing.replace_atomically

    def racing(path, write, suffix=".tmp"):
        with open(path, "a", encoding="utf-8") as other:  # opened before the rename
            real(path, write, suffix)
            other.write("# their edit\n")  # lands in the old file

    monkeypatch.setattr(writing, "replace_atomically", racing)
    result = CliRunner().invoke(cli, ["check", "--isolated", "--timeout", "0", "--fix", str(shot)])
    assert result.exit_code == 2, result.output
    assert shot.read_text(encoding="utf-8") == SHOT + "# their edit\n"
    assert "changed on disk while the fix was written" in result.output
    assert sorted(p.name for p in shot.parent.iterdir()) == ["shot.usda"]


ONE_FIX = """#usda 1.0
(
    renderSettingsPrimPath = "/Render/Settings"
)
def Scope "Render"
{
    def RenderSettings "Settings"
    {
        uniform token aspectRatioConformPolicy = "cropaperture"
    }
}
"""


@pytest.mark.parametrize("fix_to", [False, True])
def test_the_time_limit_does_not_stop_a_write_half_way(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fix_to: bool
) -> None:
    """--timeout killed the fixing worker in the middle of a write: the write's
    hidden temporary file and backup hard link stayed beside the file, which
    every later --fix then refused for its "2 hard links"."""
    shot = tmp_path / "shot.usda"
    shot.write_text(ONE_FIX, encoding="utf-8")
    real = atomic.replace_atomically

    def slow(path, write, suffix=".tmp"):
        def slow_write(temporary):
            write(temporary)
            time.sleep(4)  # past --timeout

        real(path, slow_write, suffix)

    monkeypatch.setattr(writing, "replace_atomically", slow)
    target = ["--fix-to", str(tmp_path / "fixes.usda")] if fix_to else ["--fix"]
    args = ["check", "--isolated", "--select", "SE006", "--timeout", "2", *target, str(shot)]
    result = CliRunner().invoke(cli, [*args])
    assert result.exit_code == 0, result.output
    written = tmp_path / "fixes.usda" if fix_to else shot
    assert '"cropAperture"' in written.read_text(encoding="utf-8")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["shot.usda", "fixes.usda"] if fix_to else ["shot.usda"]
    )


_SLOW_WRITE = """
import sys, time
from usdrender_lint.__main__ import main
from usdrender_lint.layers import writing
real = writing.replace_atomically

def slow(path, write, suffix=".tmp"):
    def slow_write(temporary):
        write(temporary)
        time.sleep(3)
    real(path, slow_write, suffix)

writing.replace_atomically = slow
main()
"""


@pytest.mark.parametrize("group", [False, True], ids=["command", "process-group"])
def test_sigterm_while_a_fix_is_written_lets_the_write_finish(tmp_path: Path, group: bool) -> None:
    """SIGTERM (to the command, or to its process group: a CI job cancelled) killed
    the fixing worker in the middle of a write: its temporary file and backup hard
    link stayed beside the layer."""
    shot = tmp_path / "shot.usda"
    shot.write_text(ONE_FIX, encoding="utf-8")
    driver = tmp_path / "driver.py"
    driver.write_text(_SLOW_WRITE)
    args = ["check", "--isolated", "--select", "SE006", "--fix", str(shot)]
    process = subprocess.Popen(
        [sys.executable, str(driver), *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    deadline = time.monotonic() + 60
    while not any(p.name.endswith(".orig") for p in tmp_path.iterdir()):
        assert time.monotonic() < deadline and process.poll() is None
        time.sleep(0.05)
    if group:
        os.killpg(process.pid, signal.SIGTERM)
    else:
        process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 143 and err == "usdrender-lint: terminated\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["driver.py", "shot.usda"]
    assert '"cropAperture"' in shot.read_text(encoding="utf-8")


def test_an_edit_while_the_temporary_file_is_written_is_kept(
    shot: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real = writing.replace_atomically

    def racing(path, write, suffix=".tmp"):
        def write_then_edit(temporary):
            with open(path, "a", encoding="utf-8") as other:
                other.write("# their edit\n")
            write(temporary)

        real(path, write_then_edit, suffix)

    monkeypatch.setattr(writing, "replace_atomically", racing)
    result = CliRunner().invoke(cli, ["check", "--isolated", "--timeout", "0", "--fix", str(shot)])
    assert result.exit_code == 2, result.output
    assert shot.read_text(encoding="utf-8") == SHOT + "# their edit\n"
    assert sorted(p.name for p in shot.parent.iterdir()) == ["shot.usda"]


def test_a_file_whose_owner_cannot_be_kept_is_not_fixed(
    shot: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(writing, "keep_owner", lambda path, uid, gid: False)
    result = CliRunner().invoke(cli, ["check", "--isolated", "--timeout", "0", "--fix", str(shot)])
    assert result.exit_code == 2
    assert "cannot keep its owner and group" in result.output
    assert shot.read_text(encoding="utf-8") == SHOT


# -- long names ------------------------------------------------------------------------


@pytest.mark.parametrize("length", [241, 250])
def test_long_file_names_can_be_fixed_and_written(tmp_path: Path, length: int) -> None:
    name = "s" * (length - len(".usda")) + ".usda"
    layer = tmp_path / name
    layer.write_text(SHOT, encoding="utf-8")
    report = tmp_path / ("r" * (length - len(".json")) + ".json")
    result = run(
        "check", "--isolated", "--fix", "--format", "json", "--output", str(report), str(layer)
    )
    assert result.returncode == 1, result.stderr
    assert layer.read_text(encoding="utf-8") != SHOT  # fixed
    assert json.loads(report.read_text())["summary"]["files"] == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([name, report.name])


def test_temporary_names_stay_within_name_max() -> None:
    for name in ["a.usda", "é" * 120 + ".usda", "x" * 255]:
        prefix = atomic.temporary_prefix(name, ".usda")
        assert len(os.fsencode(prefix + "12345678.usda")) <= atomic.NAME_MAX
    assert atomic.temporary_prefix("a.usda", ".usda") == ".a.usda."
    assert atomic.temporary_prefix("x" * 250, ".tmp") != atomic.temporary_prefix("x" * 251, ".tmp")


# -- devices -------------------------------------------------------------------------


def test_fix_to_dev_null_is_a_one_line_error(shot: Path) -> None:
    for extra in ([], ["--timeout", "0"]):
        result = run("check", "--isolated", *extra, "--fix-to", os.devnull, str(shot))
        assert result.returncode == 2
        assert result.stderr.startswith("usdrender-lint: error: --fix-to /dev/null: not a regular")
        assert "internal error" not in result.stderr + result.stdout


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full")
@pytest.mark.parametrize("args", [["--version"], ["--help"], ["check", "--help"]])
def test_version_and_help_onto_a_full_device(args: list[str]) -> None:
    with open("/dev/full", "w") as full:
        result = subprocess.run(
            command(*args), stdout=full, stderr=subprocess.PIPE, text=True, timeout=120
        )
    assert result.returncode == 2
    assert result.stderr == (
        "usdrender-lint: error: cannot write the output: No space left on device\n"
    )


@pytest.mark.parametrize("args", [["--version"], ["--help"]])
def test_version_and_help_to_a_reader_gone_are_a_quiet_exit_2(args: list[str]) -> None:
    read_end, write_end = os.pipe()
    os.close(read_end)  # nobody reads
    try:
        result = subprocess.run(
            command(*args), stdout=write_end, stderr=subprocess.PIPE, text=True, timeout=120
        )
    finally:
        os.close(write_end)
    assert (result.returncode, result.stderr) == (2, "")


# -- USDRENDER_LINT_DEBUG --------------------------------------------------------------

RAISING_RULE = '''
from pxr import UsdRender
from usdrender_lint.api import Rule, Severity


class Raises(Rule):
    """Raises on every product.

    ## What it does
    Nothing but raise.
    """

    code = "ZZ001"
    name = "raises"
    severity = Severity.ERROR
    prim_types = (UsdRender.Product,)

    def check_prim(self, prim, ctx):
        raise RuntimeError("raised on purpose")


RULES = [Raises]
'''


@pytest.mark.parametrize(
    "jobs", [["--jobs", "1", "--timeout", "0"], [], ["--jobs", "2"]], ids=["here", "lone", "pool"]
)
def test_debug_shows_the_traceback_of_an_internal_error(
    tmp_path: Path, shot: Path, jobs: list[str]
) -> None:
    site = tmp_path / "site"
    site.mkdir()
    (site / "raising_rules.py").write_text(textwrap.dedent(RAISING_RULE))
    info = site / "raising-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: raising\nVersion: 0.1\n")
    entry = "[usdrender_lint.rules]\nraising = raising_rules:RULES\n"
    (info / "entry_points.txt").write_text(entry)
    files = [str(shot)] if jobs != ["--jobs", "2"] else [str(shot), str(shot)]
    base = {k: v for k, v in os.environ.items() if not k.startswith("USDRENDER_LINT")}
    base["PYTHONPATH"] = os.pathsep.join(filter(None, [str(site), os.environ.get("PYTHONPATH")]))
    args = ["check", "--isolated", "--no-cache", "--select", "ZZ001", *jobs, *files]
    quiet = run(*args, env=base)
    assert "UL000" in quiet.stdout and "Traceback" not in quiet.stderr
    loud = run(*args, env={**base, "USDRENDER_LINT_DEBUG": "1"})
    assert "UL000" in loud.stdout
    assert "usdrender-lint: debug:" in loud.stderr and "Traceback" in loud.stderr
    assert 'raise RuntimeError("raised on purpose")' in loud.stderr


def test_merge_never_writes_onto_a_report_it_reads(tmp_path: Path, shot: Path) -> None:
    first = tmp_path / "first.json"
    result = run("check", "--isolated", "--format", "json", "--output", str(first), str(shot))
    assert result.returncode == 1, result.stderr
    kept = first.read_text()
    merged = run("merge", str(first), "--output", str(first))
    assert merged.returncode == 2
    assert "first.json: is an input of this run; refusing to write the merged report" in (
        merged.stderr
    )
    assert first.read_text() == kept


def test_debug_shows_the_traceback_of_a_file_that_could_not_be_linted(
    shot: Path, monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    from usdrender_lint.engine import Linter

    def broken(self, path, **kwargs):
        raise RuntimeError("the engine broke on purpose")

    monkeypatch.setattr(Linter, "lint_path", broken)
    args = ["check", "--isolated", "--no-cache", "--jobs", "1", "--timeout", "0", str(shot)]
    quiet = CliRunner().invoke(cli, args)
    assert quiet.exit_code == 2
    assert "internal error: RuntimeError: the engine broke on purpose" in quiet.stderr
    assert "Traceback" not in capfd.readouterr().err
    monkeypatch.setenv("USDRENDER_LINT_DEBUG", "1")
    loud = CliRunner().invoke(cli, args)
    assert loud.exit_code == 2
    printed = capfd.readouterr().err
    assert f"usdrender-lint: debug: {shot}: internal error" in printed
    assert "Traceback" in printed and 'raise RuntimeError("the engine broke on purpose")' in printed
