"""``check -``: a text layer on standard input gets the answer its file gets.

Every real ``.usda`` of the shared corpus and every fourth fixture goes through
the pipeline twice more than as a file: named as its own file (the language
server's "opened as saved" path) and named as a file beside it that does not
exist (the text imported into a layer of that name, as an edited buffer), and
the findings must be the file's, but for its name. The command itself, under
its supervisor, is compared byte for byte with ``check FILE``.
"""

from __future__ import annotations

import json
import os
import pty
import random
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from cli_support import command, descendants, hanging_stage, is_running
from conftest import REPO

from usdrender_lint.model import Report
from usdrender_lint.running.pipeline import FixRequest, Request, RequestError, run
from usdrender_lint.running.standard_input import (
    StandardInput,
    StandardInputError,
    decode,
    lint_standard_input,
)
from usdrender_lint.running.supervisor import (
    Supervision,
    reads_standard_input,
    wants_supervision,
)

pytestmark = pytest.mark.heavy(seconds=150)

EXAMPLES = sorted((REPO / "examples").rglob("*.usda"))
FILES = set((REPO / "tests" / "rules").rglob("*.usda"))
FIXTURES = sorted((REPO / "tests" / "rules").rglob("*.usda"))[::4]


def _answers(report: Report, name: str | None = None, as_name: str = "") -> list[tuple]:
    """The report's findings, with ``name`` (a path and its file name) read as
    ``as_name``'s, and each file's status and error."""
    out = []
    for finding in report.findings:
        text = repr((finding.code, finding.location.path, finding.location.line, finding.message))
        text += repr((finding.severity, finding.profile, finding.location.column))
        if name is not None:
            text = text.replace(name, as_name).replace(Path(name).name, Path(as_name).name)
        out.append(text)
    return sorted(out) + [repr((f.status, f.error)) for f in report.files]


def _lint(path: Path, stdin: StandardInput | None = None) -> Report:
    name = stdin.name if stdin is not None else str(path)
    request = Request((name,), isolated=True, jobs=1, timeout=None, progress=False, stdin=stdin)
    return run(request).report


def _check_as_texts(files: list[Path]) -> int:
    compared = 0
    for path in files:
        data = path.read_bytes()
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            continue  # not a text layer standard input can hold
        expected = _answers(_lint(path))
        assert _answers(_lint(path, StandardInput(text, str(path)))) == expected, path
        beside = str(path.with_name(f"{path.stem}_buffer{path.suffix}"))
        assert not os.path.exists(beside)
        as_buffer = _lint(path, StandardInput(text, beside))
        assert _answers(as_buffer, beside, str(path)) == expected, path
        compared += 1
    return compared


def test_every_fixture_and_example_as_a_text_gets_its_files_findings() -> None:
    assert _check_as_texts(EXAMPLES + FIXTURES) > 50


def test_every_real_text_layer_gets_its_files_findings(shared_dir: Path) -> None:
    files = sorted(
        p for p in (shared_dir / "corpus").rglob("*.usda") if p.stat().st_size < 1_000_000
    )
    assert _check_as_texts(files) > 100


def _command(
    *args: str, stdin: bytes | int = b"", cwd: Path = REPO, isolated: bool = True
) -> subprocess.CompletedProcess:
    """``check ARGS`` run from ``cwd``; ``isolated`` False: with the configuration
    found from there."""
    feed = {"input": stdin} if isinstance(stdin, bytes) else {"stdin": stdin}
    done = subprocess.run(
        command("check", *(["--isolated"] if isolated else []), "--no-cache", *args),
        capture_output=True,
        timeout=120,
        check=False,
        cwd=cwd,
        **feed,  # type: ignore[call-overload]
    )
    assert b"Traceback" not in done.stdout + done.stderr, done.stderr
    return done


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.parent.name + "/" + p.name)
def test_the_supervised_command_reports_a_text_as_its_file(path: Path) -> None:
    name = str(path.relative_to(REPO))
    as_file = _command("--format", "json", name)
    as_text = _command("--format", "json", "-", "--stdin-filename", name, stdin=path.read_bytes())
    assert (as_text.returncode, as_text.stdout, as_text.stderr) == (
        as_file.returncode,
        as_file.stdout,
        as_file.stderr,
    )


def test_a_text_named_with_dots_is_reported_as_the_file_so_named() -> None:
    """``--stdin-filename ./shots//a.usda`` names the text as ``check ./shots//a.usda``
    names the file: shots/a.usda, in every format."""
    path = REPO / "examples" / "broken_shot" / "shot.usda"
    dotted = "./" + str(path.relative_to(REPO)).replace("/", "//", 1)
    as_file = _command("--format", "json", dotted)
    as_text = _command("--format", "json", "-", "--stdin-filename", dotted, stdin=path.read_bytes())
    assert (as_text.returncode, as_text.stdout) == (as_file.returncode, as_file.stdout)
    assert b'"file": "examples/broken_shot/shot.usda"' in as_text.stdout


@pytest.mark.parametrize("fixing", [(), ("--diff",)])
def test_stdin_filename_with_no_path_reads_standard_input(fixing: tuple[str, ...]) -> None:
    """As ruff reads it: ``--stdin-filename NAME`` alone is ``- --stdin-filename NAME``."""
    path = REPO / "examples" / "broken_shot" / "shot.usda"
    name = str(path.relative_to(REPO))
    alone = _command(*fixing, "--stdin-filename", name, stdin=path.read_bytes())
    dash = _command(*fixing, "-", "--stdin-filename", name, stdin=path.read_bytes())
    assert (alone.returncode, alone.stdout, alone.stderr) == (1, dash.stdout, dash.stderr)
    assert alone.stdout.startswith(b"--- " if fixing else name.encode() + b":")


@pytest.mark.parametrize("text", ["shot", "parse error"])
def test_a_text_named_by_a_name_that_is_not_utf8_gets_its_files_answer(
    text: str, tmp_path: Path
) -> None:
    """USD's bindings take such a name only as bytes: the text is linted (its
    sublayer found) or its parse error told at its line, as for the file."""
    shot = REPO / "examples" / "broken_shot"
    shutil.copy(shot / "lighting_wip.usda", tmp_path)
    try:
        path = tmp_path / os.fsdecode(b"sh\xfeot.usda")
        content = (shot / "shot.usda").read_text() if text == "shot" else PARSE_ERROR
        path.write_text(content)
    except (OSError, UnicodeError):
        pytest.skip("the file system takes only UTF-8 names")
    name = path.name
    as_file = _command("--format", "json", name, cwd=tmp_path)
    as_text = _command(
        "--format", "json", "-", "--stdin-filename", name, stdin=path.read_bytes(), cwd=tmp_path
    )
    assert (as_text.returncode, as_text.stdout, as_text.stderr) == (
        as_file.returncode,
        as_file.stdout,
        as_file.stderr,
    )
    [entry] = json.loads(as_text.stdout)["files"]
    codes = sorted(f["code"] for f in entry["findings"])
    if text == "shot":
        assert (entry["status"], as_text.returncode) == ("linted", 1)
        assert codes == ["CA003", "CA004", "PR004", "SE003", "SE007"]
    else:
        [finding] = entry["findings"]
        assert (finding["code"], finding["line"]) == ("ST001", 2)
        assert finding["message"].startswith("Expected }")


#: A text USD's parser refuses at line 2 (a prim's body on its opening line).
PARSE_ERROR = '#usda 1.0\ndef Scope "S" { rel camera = </Nope> }\n'


def test_a_text_with_no_name_is_reported_as_standard_input() -> None:
    shot = REPO / "examples" / "broken_shot" / "shot.usda"
    done = _command("-", stdin=shot.read_bytes())
    assert done.returncode == 1
    assert done.stdout.startswith(b"-:32: error CA004 /Render/PrimarySettings.camera")
    broken = REPO / "examples" / "broken_shot" / "lighting_wip.usda"
    report = json.loads(_command("--format", "json", "-", stdin=broken.read_bytes()).stdout)
    [entry] = report["files"]
    [finding] = entry["findings"]
    assert (entry["file"], finding["file"], finding["layer"]) == ("-", "-", "-")
    assert (finding["code"], finding["line"], finding["message"]) == (
        "ST001",
        9,
        "Expected } at '' in </Lights/key>",
    )


def test_an_empty_standard_input_is_a_layer_usd_cannot_read() -> None:
    with open(os.devnull, "rb") as nothing:
        done = _command("-", stdin=nothing.fileno())
    assert done.returncode == 1
    assert b"error ST001" in done.stdout


def test_relative_asset_paths_and_the_configuration_are_found_from_its_name(
    tmp_path: Path,
) -> None:
    shot = tmp_path / "shots" / "a"
    shot.mkdir(parents=True)
    (shot / "cam.usda").write_text('#usda 1.0\ndef Camera "Cam"\n{\n}\n')
    text = (
        b'#usda 1.0\ndef "World" (\n    references = @./cam.usda@</Cam>\n)\n{\n}\n'
        b'def RenderSettings "S"\n{\n    rel camera = </World>\n'
        b"    uniform bool instantaneousShutter = true\n}\n"
    )
    elsewhere = _command(
        "--format",
        "json",
        "-",
        "--stdin-filename",
        "x.usda",
        stdin=text,
        cwd=tmp_path,
        isolated=False,
    )
    [entry] = json.loads(elsewhere.stdout)["files"]
    codes = {f["code"] for f in entry["findings"]}
    assert {"SE007", "CA004"} <= codes  # ./cam.usda is not beside x.usda: no Camera
    (tmp_path / "shots" / ".usdrender-lint.toml").write_text('ignore = ["SE007"]\n')
    beside = _command(
        "--format",
        "json",
        "-",
        "--stdin-filename",
        "a/s.usda",
        stdin=text,
        cwd=tmp_path / "shots",
        isolated=False,
    )
    [entry] = json.loads(beside.stdout)["files"]
    assert entry["file"] == "a/s.usda"
    assert not {f["code"] for f in entry["findings"]} & {"SE007", "CA004"}
    assert sorted(p.name for p in shot.iterdir()) == ["cam.usda"]  # nothing written


@pytest.mark.parametrize(
    ("args", "data", "says"),
    [
        (("-",), b"PXR-USDC\x00\x00", "-: standard input holds a binary crate (.usdc)"),
        (("-",), b"PK\x03\x04rest", "-: standard input holds a package (.usdz)"),
        (("-", "--stdin-filename", "s.usda"), b"#usda 1.0\n\xff\n", "s.usda: standard input "),
        # USD cannot make a layer inside a package from a text (an internal error before).
        (
            ("-", "--stdin-filename", "pkg.usdz[inner.usda]"),
            b"#usda 1.0\n",
            "pkg.usdz[inner.usda]: names a layer inside a package",
        ),
        (
            ("-", "--stdin-filename", "s.usda:SDF_FORMAT_ARGS:a=b"),
            b"#usda 1.0\n",
            "s.usda:SDF_FORMAT_ARGS:a=b: holds file format arguments",
        ),
        (("-", "examples/clean_shot/shot.usda"), b"#usda 1.0\n", "is linted alone"),
        (("--stdin-filename", "s.usda", "examples"), b"", "give '-' or no path, not 'examples'"),
        (("--fix-to", "o.usda", "-"), b"#usda 1.0\n", "cannot be combined with --fix-to"),
        (("--shard", "1/2", "-"), b"#usda 1.0\n", "cannot be combined with --fix-to or --shard"),
        (("--format", "html", "-"), b"#usda 1.0\n", "cannot be combined with --format html"),
        (("--format", "full", "-"), b"#usda 1.0\n", "cannot be combined with --format full"),
    ],
)
def test_what_cannot_be_linted_from_standard_input_says_why(
    args: tuple[str, ...], data: bytes, says: str
) -> None:
    done = _command(*args, stdin=data)
    assert done.returncode == 2
    [line] = done.stderr.decode().splitlines()
    assert line.startswith("usdrender-lint: error: ") and says in line, line
    assert done.stdout == b""


@pytest.mark.parametrize(
    ("given", "how"),
    [(("-",), "'-'"), (("--stdin-filename", "s.usda"), "'--stdin-filename s.usda'")],
)
def test_a_terminal_on_standard_input_is_refused_at_once(given: tuple[str, ...], how: str) -> None:
    leader, follower = pty.openpty()
    try:
        done = _command(*given, stdin=follower)
    finally:
        os.close(leader)
        os.close(follower)
    assert done.returncode == 2
    assert f"{how} reads a text layer from standard input, which is a terminal".encode() in (
        done.stderr
    )


def test_decode_reads_utf8_text_and_refuses_the_rest() -> None:
    text = "#usda 1.0\n# é\n"
    assert decode(text.encode(), "s.usda") == StandardInput(text, "s.usda")
    with pytest.raises(StandardInputError, match="byte 0xe9 at offset 12"):
        decode("#usda 1.0\n# é\n".encode("latin-1"))


def test_only_a_check_of_dash_reads_standard_input_before_the_fork() -> None:
    assert reads_standard_input(["check", "-"]) is not os.isatty(0)
    assert not reads_standard_input(["check", "shot.usda"])
    assert not reads_standard_input(["spec", "-"])
    assert reads_standard_input(["check", "--stdin-filename", "s.usda"]) is not os.isatty(0)
    assert not reads_standard_input(["check", "--stdin-filename", "s.usda", "shot.usda"])


def _prepared():
    from usdrender_lint.running.pipeline import prepare

    return prepare(Request(("-",), isolated=True, jobs=1, timeout=None, progress=False))


@pytest.mark.parametrize(
    ("ending", "why"),
    [
        ("timeout", "-: timed out after 3 s (raise --timeout, or 0 for no limit)"),
        ("crash", "-: the linter process crashed while reading it"),
    ],
)
def test_after_the_child_ends_on_it_the_supervisor_reports_that(ending: str, why: str) -> None:
    given = StandardInput("#usda 1.0\n")
    result = lint_standard_input(_prepared(), given, Supervision(ending=ending), 3)
    assert (result.file, result.status, result.error) == ("-", "error", why)


def test_fix_to_and_shards_are_refused_by_the_pipeline_too() -> None:
    given = StandardInput("#usda 1.0\n")
    for request in (
        Request(("-",), isolated=True, stdin=given, fix=FixRequest(fix_to="o.usda")),
        Request(("-",), isolated=True, stdin=given, shard=(1, 2)),
    ):
        with pytest.raises(RequestError, match="standard input"):
            run(request)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the supervisor is Linux's")
@pytest.mark.parametrize("crash", [False, True], ids=["time-out", "crash"])
def test_a_text_that_hangs_usd_ends_as_its_error(tmp_path: Path, crash: bool) -> None:
    """The supervisor read the text before its fork: its child's time-out or
    crash is the text's error, and nothing waits on standard input again."""
    stage = hanging_stage(tmp_path)
    args = ("check", "--isolated", "--no-cache", "--format", "json", "--timeout", "4", "-")
    with stage.open("rb") as text:
        process = subprocess.Popen(
            [*command(*args), "--stdin-filename", str(tmp_path / "buffer.usda")],
            stdin=text,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
        )
    if crash:
        deadline = time.monotonic() + 60
        while not descendants(process.pid) and time.monotonic() < deadline:
            time.sleep(0.05)
        [child] = descendants(process.pid)
        time.sleep(1.0)  # in USD, blocked on the FIFO
        os.kill(child, signal.SIGSEGV)
    stdout, stderr = process.communicate(timeout=60)
    [entry] = json.loads(stdout)["files"]
    why = "the linter process crashed while reading it" if crash else "timed out after 4 s"
    assert entry["status"] == "error" and why in entry["error"], entry
    assert process.returncode == 2
    assert stderr.decode().startswith(f"usdrender-lint: error: {tmp_path / 'buffer.usda'}: ")
    if crash:
        assert not is_running(child)


def test_an_engine_failure_is_the_texts_error_not_the_runs(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from usdrender_lint.running.documents import Documents

    def fails(self: Documents, path: str) -> None:
        raise RuntimeError("boom\nsecond line")

    monkeypatch.setattr(Documents, "lint", fails)
    result = lint_standard_input(_prepared(), StandardInput("#usda 1.0\n", "s.usda"))
    assert (result.file, result.status, result.error) == (
        "s.usda",
        "error",
        "s.usda: internal error: RuntimeError: boom second line",
    )


def test_a_text_nesting_too_deep_for_usd_is_refused_as_its_file_is(tmp_path: Path) -> None:
    """USD's parser overflows its stack on such a text (the child died of it):
    the nesting bound the file gets applies to the text before USD reads it."""
    deep = tmp_path / "deep.usda"
    deep.write_text("#usda 1.0\n" + 'def "A" {\n' * 12_000 + "}\n" * 12_000)
    as_file = _command("--format", "json", "deep.usda", cwd=tmp_path)
    for name in ("deep.usda", "buffer.usda"):  # opened as saved, and imported
        as_text = _command(
            "--format", "json", "-", "--stdin-filename", name, stdin=deep.read_bytes(), cwd=tmp_path
        )
        assert as_text.returncode == as_file.returncode == 1
        expected = as_file.stdout.replace(b"deep.usda", name.encode())
        assert as_text.stdout == expected
    [finding] = json.loads(as_file.stdout)["files"][0]["findings"]
    assert finding["code"] == "ST001" and "nests 12,000 levels deep" in finding["message"]


# -- fixing the text: its output is what --fix writes into the file ------------------


def _fixed_as_file(folder: Path, name: str, fix: FixRequest) -> tuple[str, set[str]] | None:
    """The text ``check --fix`` leaves in ``folder/name`` (a copy), and the files
    it changed; None when a fix edits another file (the text cannot get it)."""
    before = {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}
    run(Request((str(folder / name),), isolated=True, jobs=1, timeout=None, fix=fix))
    changed = {p.name for p in folder.iterdir() if p.is_file() and before[p.name] != p.read_bytes()}
    if changed - {name}:
        return None
    return (folder / name).read_bytes().decode("utf-8"), changed  # line endings as written


@pytest.mark.parametrize("unsafe", [False, True], ids=["safe", "unsafe"])
def test_fixing_a_text_gives_what_fixing_its_file_writes(tmp_path: Path, unsafe: bool) -> None:
    """Every failing fixture with a fix, and the examples: --fix - prints what
    --fix writes into a copy of the file (fixtures whose fix edits another of
    their files are left out: a text's fixes write no file)."""
    fixed = (REPO / "tests" / "rules").rglob("*.fixed.usda")
    fixtures = sorted({p.with_name(p.name.replace(".fixed", "")) for p in fixed} & FILES)
    compared = 0
    for index, path in enumerate([*EXAMPLES, *fixtures]):
        copy = tmp_path / str(index)
        copy.mkdir()
        for sibling in path.parent.iterdir():
            if sibling.is_file() and sibling.suffix.startswith(".usd"):
                (copy / sibling.name).write_bytes(sibling.read_bytes())
        text = path.read_text(encoding="utf-8")
        name = str(copy / path.name)
        fix = FixRequest(unsafe=unsafe)
        given = StandardInput(text, name)
        outcome = run(Request((name,), isolated=True, jobs=1, timeout=None, fix=fix, stdin=given))
        assert (copy / path.name).read_text(encoding="utf-8") == text  # nothing written
        expected = _fixed_as_file(copy, path.name, fix)
        if expected is None:
            continue
        assert outcome.text == expected[0], path
        assert (outcome.text != text) == bool(expected[1]) == bool(outcome.report.applied_fixes)
        compared += 1
    assert compared > 40


def test_the_diff_of_a_text_is_the_diff_of_its_file() -> None:
    patches = b""
    for path in EXAMPLES:
        name = str(path.relative_to(REPO))
        as_file = _command("--diff", name)
        as_text = _command("--diff", "-", "--stdin-filename", name, stdin=path.read_bytes())
        assert (as_text.returncode, as_text.stdout, as_text.stderr) == (
            as_file.returncode,
            as_file.stdout,
            as_file.stderr,
        )
        patches += as_text.stdout
    assert b"+        rel camera = </World/camRig/shotCam>" in patches


def test_the_fixed_text_is_the_output_and_the_report_goes_to_output(tmp_path: Path) -> None:
    shot = REPO / "examples" / "broken_shot" / "shot.usda"
    text = shot.read_text(encoding="utf-8").replace("# CA004:", "# CA004 (é):")
    report = tmp_path / "report.json"
    done = subprocess.run(
        command("check", "--isolated", "--fix", "-", "--output", str(report), "--format", "json"),
        input=text.encode(),
        capture_output=True,
        timeout=120,
        check=False,
        env={**os.environ, "PYTHONIOENCODING": "latin-1"},  # the text stays UTF-8
    )
    assert done.returncode == 1  # errors remain
    fixed = done.stdout.decode("utf-8")
    assert "rel camera = </World/camRig/shotCam>" in fixed and "# CA004 (é):" in fixed
    unfixed = fixed.replace("</World/camRig/shotCam>", "</World/camRig>")
    assert unfixed.replace("bool disableMotionBlur", "bool instantaneousShutter") == text
    [entry] = json.loads(report.read_text())["files"]
    assert {f["code"] for f in entry["findings"]} == {"CA003", "SE003", "PR004"}


def test_a_fix_of_a_file_the_text_composes_is_not_applied(tmp_path: Path) -> None:
    sub = tmp_path / "sub.usda"
    sub.write_text(
        '#usda 1.0\nover "Render"\n{\n    over "S"\n    {\n'
        "        uniform bool instantaneousShutter = 1\n    }\n}\n"
    )
    text = (
        b'#usda 1.0\n(\n    subLayers = [@./sub.usda@]\n)\ndef Scope "Render"\n{\n'
        b'    def RenderSettings "S"\n    {\n    }\n}\n'
    )
    before = sub.read_bytes()
    done = _command("--fix", "-", "--stdin-filename", "top.usda", stdin=text, cwd=tmp_path)
    assert sub.read_bytes() == before
    assert b"1 fix not applied (SE007): sub.usda is a file, and fixes of standard input's" in (
        done.stderr
    )
    assert done.stdout == text.replace(
        b"[@./sub.usda@]\n", b'[@./sub.usda@]\n    renderSettingsPrimPath = "/Render/S"\n'
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sub.usda"]


@pytest.mark.parametrize(
    ("argv", "supervised"),
    [
        (["check", "--fix", "-"], True),
        (["check", "--diff", "--unsafe-fixes", "-"], True),
        (["check", "--fix-to", "o.usda", "-"], False),
        (["check", "--write-baseline", "b.json", "-"], False),
        (["check", "--fix", "shot.usda"], False),
    ],
)
def test_fixing_a_text_is_supervised_as_it_writes_no_file(
    argv: list[str], supervised: bool
) -> None:
    assert wants_supervision(argv) is (supervised and sys.platform.startswith("linux"))


#: What seeded mutations insert: the characters and words of USD's grammar.
_TOKENS = ("{", "}", "(", ")", "[", "]", '"', "@", "<", ">", "=", "\n", "def ", "rel ", "-", "é")


def _mutated(text: str, rng: random.Random) -> str:
    for _ in range(rng.randint(1, 4)):
        at = rng.randrange(len(text))
        roll = rng.random()
        if roll < 0.4:
            text = text[:at] + text[at + rng.randint(1, 20) :]
        elif roll < 0.8:
            text = text[:at] + rng.choice(_TOKENS) + text[at:]
        else:
            start = rng.randrange(len(text))
            text = text[:at] + text[start : start + rng.randint(1, 40)] + text[at:]
    return text


def test_broken_texts_get_the_answer_their_files_get(tmp_path: Path) -> None:
    """Seeded mutations of the examples and fixtures (most of them texts USD
    cannot parse): as an unsaved buffer each gets its file's findings, every
    error line of USD's placed as the file's are, a header USD's format check
    refuses included."""
    rng = random.Random(27)
    sources = [p.read_text() for p in [*EXAMPLES, *FIXTURES[::3]]]
    compared = 0
    for _ in range(120):
        text = _mutated(rng.choice(sources), rng)
        path = tmp_path / "shot.usda"
        path.write_text(text, encoding="utf-8")
        buffer = str(tmp_path / "buffer.usda")
        expected = _answers(_lint(path))
        assert _answers(_lint(path, StandardInput(text, buffer)), buffer, str(path)) == expected
        compared += 1
    assert compared == 120


@pytest.mark.parametrize("suffix", [".usda", ".usd"])
@pytest.mark.parametrize(
    "head",
    ["", "def Xform", " #usda 1.0", "#sdf 1.4.32", "\ufeff#usda 1.0", "#usd", "#usda", "#usda 9.9"],
)
def test_a_text_whose_header_usd_refuses_gets_its_files_answer(
    tmp_path: Path, head: str, suffix: str
) -> None:
    """USD refuses a file that does not start with ``#usda`` before parsing it,
    where ImportFromString parsed any text (or accepted it: a leading space)."""
    text = f'{head}\ndef Scope "Render" {{}}\n' if head else ""
    path = tmp_path / f"shot{suffix}"
    path.write_text(text, encoding="utf-8")
    buffer = str(tmp_path / f"buffer{suffix}")
    expected = _answers(_lint(path))
    assert any("ST001" in answer for answer in expected)
    assert _answers(_lint(path, StandardInput(text, buffer)), buffer, str(path)) == expected


def test_a_configurations_roots_do_not_apply_to_a_text(tmp_path: Path) -> None:
    """With ``roots`` a changed layer is linted inside the shots that use it; a
    text is linted as a stage of its own (as the language server lints it)."""
    (tmp_path / "shots").mkdir()
    (tmp_path / "shots" / "shot.usda").write_text(
        '#usda 1.0\n(\n    subLayers = [@../light.usda@]\n)\ndef Camera "Cam"\n{\n}\n'
    )
    (tmp_path / "pyproject.toml").write_text('[tool.usdrender-lint]\nroots = ["shots/*.usda"]\n')
    light = b'#usda 1.0\ndef RenderSettings "S"\n{\n    rel camera = </Cam>\n}\n'
    (tmp_path / "light.usda").write_bytes(light)
    as_file = json.loads(
        _command("--format", "json", "light.usda", cwd=tmp_path, isolated=False).stdout
    )["files"]
    as_text = _command(
        "--format",
        "json",
        "-",
        "--stdin-filename",
        "light.usda",
        stdin=light,
        cwd=tmp_path,
        isolated=False,
    )
    [entry] = json.loads(as_text.stdout)["files"]
    assert entry["file"] == "light.usda"
    # Alone, </Cam> is missing (the shot defines it); inside its root it is there.
    assert "CA003" in {f["code"] for f in entry["findings"]}
    assert "CA003" not in {f["code"] for e in as_file for f in e["findings"]}


def test_a_text_with_windows_line_endings_is_fixed_as_its_file(tmp_path: Path) -> None:
    """A Windows editor's buffer (CRLF): the fixed text keeps its line endings,
    as --fix keeps the file's."""
    text = (REPO / "examples" / "broken_shot" / "shot.usda").read_text().replace("\n", "\r\n")
    (tmp_path / "shot.usda").write_bytes(text.encode())
    name = str(tmp_path / "shot.usda")
    fixed = run(
        Request((name,), isolated=True, jobs=1, timeout=None, fix=FixRequest(),
                stdin=StandardInput(text, name))
    ).text  # fmt: skip
    expected = _fixed_as_file(tmp_path, "shot.usda", FixRequest())
    assert expected is not None and fixed == expected[0] != text
    assert fixed is not None and fixed.count("\r\n") == fixed.count("\n")


@pytest.mark.parametrize("text", ["hello\n", "", "\ufeff#usda 1.0\n"])
def test_an_unnamed_text_s_messages_name_it_as_the_report_does(text: str) -> None:
    """USD names the layer an unnamed text stands in for (``-.usda``), a name
    the user never gave: the messages say ``-``, as the report's file does."""
    done = subprocess.run(
        [*command(), "check", "--isolated", "--format", "json", "-"],
        input=text,
        capture_output=True,
        text=True,
    )
    (entry,) = json.loads(done.stdout)["files"]
    assert entry["file"] == "-"
    messages = [f["message"] for f in entry["findings"]]
    assert messages and all("-.usda" not in m for m in messages)
    assert any(m.startswith("<-> is not a valid usda layer") for m in messages)
