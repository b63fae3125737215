"""Every byte of a report reaches its reader, or the run says it did not.

- A reader that goes away early (``check | head -c 10``) ends the run with
  exit 2 and nothing said, whatever the format and the report's size: one
  ``write()`` of a report larger than the pipe takes part of it and reports no
  error, so the writing goes on until the report is out or the pipe breaks.
- ``--output`` (and ``spec --output``, ``--write-baseline``) onto
  ``/dev/stdout``, ``/dev/stderr``, a pipe, a FIFO or a terminal streams into
  it; onto a regular file that stdout is redirected to, it writes through the
  descriptor, so ``{ echo A; check --output /dev/stdout; echo B; } >> log``
  keeps A, B and what the log held; a regular file named as such is replaced
  atomically, keeping its owner and mode.
"""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from usdrender_lint import atomic
from usdrender_lint.formatters import available_formatters

pytestmark = pytest.mark.heavy(seconds=48)

REPO = Path(__file__).resolve().parents[2]
BROKEN = str(REPO / "examples" / "broken_shot" / "shot.usda")
#: Every registered report format (json, sarif, text, github, html, ...).
FORMATS = sorted(available_formatters())


def command(*args: str) -> list[str]:
    return [sys.executable, "-m", "usdrender_lint", *args]


@pytest.fixture(scope="module")
def big_stage(tmp_path_factory: pytest.TempPathFactory) -> str:
    """A layer whose report is larger than a pipe's buffer in every format."""
    path = tmp_path_factory.mktemp("big") / "many_vars.usda"
    body = "".join(f'    def RenderVar "v{i}" {{ }}\n' for i in range(300))
    path.write_text(f'#usda 1.0\ndef Scope "Render"\n{{\n{body}}}\n')
    return str(path)


@pytest.mark.parametrize("output_format", FORMATS)
def test_a_reader_that_reads_a_little_and_leaves_is_a_quiet_exit_2(
    big_stage: str, output_format: str
) -> None:
    args = ["check", "--isolated", "--show-info", "--format", output_format, big_stage]
    process = subprocess.Popen(command(*args), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert process.stdout is not None and process.stderr is not None
    assert len(process.stdout.read(10)) == 10
    process.stdout.close()  # gone, with most of the report unread
    stderr = process.stderr.read()
    assert (process.wait(120), stderr) == (2, b"")


@pytest.mark.parametrize("output_format", ["json", "text"])
def test_a_reader_that_reads_it_all_gets_it_all(big_stage: str, output_format: str) -> None:
    args = ["check", "--isolated", "--show-info", "--format", output_format, big_stage]
    done = subprocess.run(command(*args), capture_output=True, timeout=120)
    assert done.returncode == 1, done.stderr
    assert len(done.stdout) > 1 << 16
    if output_format == "json":
        assert json.loads(done.stdout)["summary"]["files"] == 1


@pytest.mark.parametrize("output_format", FORMATS)
def test_a_pipe_gets_utf8_whatever_the_locale(tmp_path: Path, output_format: str) -> None:
    # The bytes --output writes, which JSON, SARIF and the XML declaration say
    # are UTF-8: not an internal error where stdout's encoding is ASCII.
    layer = tmp_path / "色.usda"
    layer.write_text(Path(BROKEN).read_text(encoding="utf-8"), encoding="utf-8")
    args = ["check", "--isolated", "--no-cache", "--format", output_format, str(layer)]
    env = {**os.environ, "PYTHONIOENCODING": "ascii"}  # as a Windows console's cp1252
    piped = subprocess.run(command(*args), capture_output=True, timeout=120, env=env)
    assert piped.returncode == 1, piped.stderr
    report = tmp_path / "report"
    subprocess.run(command(*args, "--output", str(report)), timeout=120, env=env, check=False)
    assert piped.stdout == report.read_bytes()
    assert not piped.stdout.isascii()
    piped.stdout.decode("utf-8")


def test_write_all_writes_what_one_write_leaves(monkeypatch: pytest.MonkeyPatch) -> None:
    read_end, write_end = os.pipe()
    real_write = os.write

    def short(fd: int, data: bytes) -> int:
        return real_write(fd, bytes(data[:3]))  # a pipe taking part of each write

    monkeypatch.setattr(atomic.os, "write", short)
    try:
        atomic.write_all(write_end, b"0123456789")
    finally:
        monkeypatch.undo()
        os.close(write_end)
    assert os.read(read_end, 100) == b"0123456789"
    os.close(read_end)


def test_write_all_reports_a_reader_gone() -> None:
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        with pytest.raises(BrokenPipeError):
            atomic.write_all(write_end, b"x" * (1 << 20))
    finally:
        os.close(write_end)


# -- --output onto streams and descriptors ------------------------------------------

WRITERS = {
    "--output": ["check", "--isolated", "--format", "json", "--output", "{}", BROKEN],
    # The report goes elsewhere: the baseline is stdout's only text.
    "--write-baseline": ["check", "--isolated", "--output", os.devnull, "--write-baseline", "{}"]
    + [BROKEN],
    "spec --output": ["spec", "--isolated", "--format", "json", "--output", "{}", BROKEN],
}


def _args(writer: str, target: str) -> list[str]:
    return [target if arg == "{}" else arg for arg in WRITERS[writer]]


def _document(text: str) -> dict:
    return json.loads(text)


@pytest.mark.parametrize("writer", list(WRITERS))
@pytest.mark.parametrize("append", [False, True])
def test_output_to_dev_stdout_redirected_to_a_file_keeps_the_file(
    tmp_path: Path, writer: str, append: bool
) -> None:
    """``{ echo BEFORE; check --output /dev/stdout; echo AFTER; } > log`` and ``>> log``."""
    log = tmp_path / "log"
    log.write_text("EARLIER\n" if append else "")
    with open(log, "a" if append else "w") as out:
        out.write("BEFORE\n")
        out.flush()
        done = subprocess.run(
            command(*_args(writer, "/dev/stdout")), stdout=out, stderr=subprocess.PIPE, timeout=120
        )
        out.write("AFTER\n")
    assert done.returncode in (0, 1), done.stderr
    text = log.read_text()
    head = "EARLIER\nBEFORE\n" if append else "BEFORE\n"
    assert text.startswith(head) and text.endswith("}\nAFTER\n"), text[:200]
    _document(text[len(head) : -len("AFTER\n")])
    assert stat.S_ISREG(os.lstat(log).st_mode)


@pytest.mark.parametrize("writer", list(WRITERS))
@pytest.mark.parametrize("name", ["/dev/stdout", "/dev/stderr", "/dev/fd/{fd}"])
def test_output_to_a_pipe_by_any_name(writer: str, name: str) -> None:
    read_end, write_end = os.pipe()
    target = name.format(fd=write_end)
    stream = {"/dev/stdout": "stdout", "/dev/stderr": "stderr"}.get(name)
    with os.fdopen(read_end, "rb") as reader:
        process = subprocess.Popen(
            command(*_args(writer, target)),
            stdout=write_end if stream == "stdout" else subprocess.DEVNULL,
            stderr=write_end if stream == "stderr" else subprocess.DEVNULL,
            pass_fds=(write_end,),
        )
        os.close(write_end)
        received = reader.read()
    assert process.wait(120) in (0, 1)
    text = received.decode()
    _document(text[: text.rindex("}") + 1])


@pytest.mark.skipif(not hasattr(os, "openpty"), reason="no terminals")
@pytest.mark.parametrize("writer", ["--output", "spec --output"])
def test_output_to_a_terminal_streams_into_it(writer: str) -> None:
    leader, follower = os.openpty()
    terminal = os.ttyname(follower)
    if not os.path.exists(terminal):  # no /dev/pts here: the terminal by its descriptor
        terminal = f"/dev/fd/{follower}"
    before = os.fstat(follower)
    chunks: list[bytes] = []

    def read() -> None:  # a terminal's buffer is small: read while it writes
        while True:
            try:
                chunk = os.read(leader, 1 << 16)
            except OSError:  # EIO: the terminal has no writer left
                return
            if not chunk:
                return
            chunks.append(chunk)

    reader = threading.Thread(target=read)
    reader.start()
    try:
        done = subprocess.run(
            command(*_args(writer, terminal)),
            capture_output=True,
            timeout=120,
            pass_fds=(follower,),
        )
        after = os.fstat(follower)
    finally:
        os.close(follower)
        reader.join(60)
        os.close(leader)
    received = b"".join(chunks)
    assert done.returncode in (0, 1), done.stderr
    _document(received.decode().replace("\r\n", "\n"))
    assert stat.S_ISCHR(after.st_mode) and before.st_rdev == after.st_rdev


@pytest.mark.skipif(os.geteuid() != 0, reason="only root may give a file to another user")
@pytest.mark.parametrize("writer", list(WRITERS))
def test_output_onto_another_users_file_keeps_owner_and_mode(tmp_path: Path, writer: str) -> None:
    target = tmp_path / "report.json"
    target.write_text("old")
    os.chown(target, 4321, 8765)
    target.chmod(0o600)
    done = subprocess.run(command(*_args(writer, str(target))), capture_output=True, timeout=120)
    assert done.returncode in (0, 1), done.stderr
    _document(target.read_text())
    now = target.stat()
    assert (now.st_uid, now.st_gid, stat.S_IMODE(now.st_mode)) == (4321, 8765, 0o600)


def test_a_file_whose_owner_cannot_be_kept_is_written_in_place(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    target = tmp_path / "report.json"
    target.write_text("old and longer than the new text")
    target.chmod(0o640)
    inode = target.stat().st_ino
    monkeypatch.setattr(atomic, "keep_owner", lambda path, uid, gid: False)
    atomic.write_output(target, "new")
    assert target.read_text() == "new"
    assert target.stat().st_ino == inode  # not replaced: owner, group and mode kept
    assert stat.S_IMODE(target.stat().st_mode) == 0o640
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.json"]


@pytest.mark.parametrize(
    ("path", "expected"),
    [
        ("/dev/stdout", 1),
        ("/dev/stderr", 2),
        ("/dev/fd/7", 7),
        ("/proc/self/fd/5", 5),
        # This process's own number, filled in when the test runs: the test's
        # name stays the same in every xdist worker, which collect apart.
        ("/proc/{pid}/fd/4", 4),
        ("/proc/1/fd/4", None),  # another process's: a file like any
        ("/tmp/report.json", None),
    ],
)
def test_named_descriptors(path: str, expected: int | None) -> None:
    assert atomic.named_descriptor(path.format(pid=os.getpid())) == expected


def test_a_link_to_dev_stdout_names_stdout(tmp_path: Path) -> None:
    link = tmp_path / "report.json"
    link.symlink_to("/dev/stdout")
    assert atomic.named_descriptor(link) == 1


@pytest.mark.parametrize(
    "args",
    [
        ("check", "--isolated", "--format", "json", BROKEN),
        ("spec", "--isolated", "--format", "json", BROKEN),
    ],
)
def test_output_dash_is_stdout_not_a_file_named_dash(tmp_path: Path, args: tuple) -> None:
    """``-`` names standard input among the paths; as ``--output`` it is stdout."""
    plain = subprocess.run(command(*args), capture_output=True, cwd=tmp_path, timeout=120)
    dashed = subprocess.run(
        command(*args[:1], "--output", "-", *args[1:]),
        capture_output=True,
        cwd=tmp_path,
        timeout=120,
    )
    assert (dashed.returncode, dashed.stdout) == (plain.returncode, plain.stdout)
    assert json.loads(dashed.stdout) and not (tmp_path / "-").exists()


def _on_a_terminal(
    cwd: Path, *args: str, env: dict[str, str] | None = None, columns: int = 0
) -> str:
    """What a terminal (``columns`` wide when given) shows for ``usdrender-lint
    *args`` (stdout and stderr both on it)."""
    leader, follower = os.openpty()
    if columns:
        import fcntl
        import struct
        import termios

        fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 50, columns, 0, 0))
    env = env or {**os.environ, "NO_COLOR": "1", "COLUMNS": "200"}
    proc = subprocess.Popen(
        [sys.executable, "-m", "usdrender_lint", *args],
        cwd=cwd,
        stdin=subprocess.DEVNULL,
        stdout=follower,
        stderr=follower,
        env=env,
    )
    os.close(follower)
    chunks = []
    while True:
        try:
            chunk = os.read(leader, 65536)
        except OSError:  # EIO: the command closed the terminal
            break
        if not chunk:
            break
        chunks.append(chunk)
    proc.wait(timeout=120)
    os.close(leader)
    return b"".join(chunks).decode("utf-8", "replace").replace("\r\n", "\n")


@pytest.mark.skipif(sys.platform == "win32", reason="a pseudo-terminal")
@pytest.mark.parametrize("command", ["check", "spec"])
def test_a_file_not_linted_reads_once_on_a_terminal(tmp_path: Path, command: str) -> None:
    # The text report names it; stderr repeats it only for a log or a file report.
    shown = _on_a_terminal(tmp_path, command, "--isolated", "-j1", "nope.usda")
    assert shown.count("no such file") == 1, shown


@pytest.mark.skipif(sys.platform == "win32", reason="a pseudo-terminal")
@pytest.mark.parametrize(("columns", "longest"), [(150, 150), (0, None)])
def test_a_dumb_terminal_wraps_at_its_own_width_not_80(
    tmp_path: Path, columns: int, longest: int | None
) -> None:
    """TERM=dumb (an editor's shell buffer) is as wide as the terminal says, or
    COLUMNS: rich alone would call it 80 columns wide. Of unknown width, the
    finding stays one line and the display wraps it."""
    env = {k: v for k, v in os.environ.items() if k not in ("COLUMNS", "LINES", "NO_COLOR")}
    env["TERM"] = "dumb"
    shown = _on_a_terminal(tmp_path, "check", "--isolated", BROKEN, env=env, columns=columns)
    lines = shown.splitlines()
    assert "\x1b[" not in shown  # a dumb terminal gets no colour
    if longest is None:
        assert not any(line.startswith("    ") for line in lines), shown
        assert max(len(line) for line in lines) > 150
    else:
        assert any(line.startswith("    ") for line in lines), shown  # wrapped...
        assert 80 < max(len(line) for line in lines) <= longest, shown  # ...at its width


@pytest.mark.skipif(sys.platform == "win32", reason="a pseudo-terminal")
def test_a_dumb_terminal_takes_columns_from_the_environment(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("LINES", "NO_COLOR")}
    env.update(TERM="dumb", COLUMNS="120")
    lines = _on_a_terminal(tmp_path, "check", "--isolated", BROKEN, env=env).splitlines()
    assert 80 < max(len(line) for line in lines) <= 120
