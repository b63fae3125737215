"""Helpers of the HTML report's tests: a strict structural check of a page,
what it would fetch, and Debian's headless Chromium (the tests skip without it)."""

from __future__ import annotations

import shutil
import subprocess
import tempfile
import zlib
from html.parser import HTMLParser
from pathlib import Path

VOID = {
    "area",
    "base",
    "br",
    "col",
    "embed",
    "hr",
    "img",
    "input",
    "link",
    "meta",
    "source",
    "track",
    "wbr",
}
#: Elements whose end tag HTML lets the parser imply: the page closes them anyway.
SVG_SELF_CLOSING_OK = True
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


class StrictCheck(HTMLParser):
    """Every element closed in order, ids unique, one doctype, nothing fetched."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.stack: list[str] = []
        self.ids: set[str] = set()
        self.problems: list[str] = []
        self.fetches: list[str] = []
        self.doctype = 0

    def handle_decl(self, decl: str) -> None:
        self.doctype += decl.lower() == "doctype html"

    def handle_starttag(self, tag: str, attrs) -> None:
        self._attrs(tag, attrs)
        if tag not in VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag: str, attrs) -> None:
        self._attrs(tag, attrs)  # <path/> inside SVG: complete as written

    def handle_endtag(self, tag: str) -> None:
        if not self.stack or self.stack[-1] != tag:
            self.problems.append(
                f"</{tag}> closes {self.stack[-1:] or 'nothing'} at {self.getpos()}"
            )
            if tag in self.stack:
                while self.stack.pop() != tag:
                    pass
            return
        self.stack.pop()

    def _attrs(self, tag: str, attrs) -> None:
        for name, value in attrs:
            if name == "id":
                if value in self.ids:
                    self.problems.append(f"duplicate id {value!r}")
                self.ids.add(value)
            if name in ("src", "srcset", "data", "poster", "action") or (
                name == "href" and not (value or "").startswith("#")
            ):
                self.fetches.append(f"<{tag} {name}={value!r}>")
        if tag == "link":
            self.fetches.append("<link>")


def strict_problems(text: str) -> tuple[list[str], list[str]]:
    """(structural problems, what the page would fetch) of an HTML page."""
    check = StrictCheck()
    check.feed(text)
    check.close()
    problems = list(check.problems)
    if check.stack:
        problems.append(f"never closed: {check.stack}")
    if check.doctype != 1:
        problems.append("not exactly one <!DOCTYPE html>")
    return problems, check.fetches


def chromium() -> str | None:
    return shutil.which("chromium") or shutil.which("chromium-browser")


def run_chromium(url: str, *args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    with tempfile.TemporaryDirectory(prefix="chromium-profile-") as profile:
        return subprocess.run(
            [chromium() or "chromium", *CHROMIUM_FLAGS, f"--user-data-dir={profile}", *args, url],
            capture_output=True,
            text=True,
            timeout=timeout,
            check=False,
        )


def screenshot(url: str, out: Path, size: str = "1440,900") -> Path:
    run = run_chromium(url, f"--screenshot={out}", f"--window-size={size}")
    assert out.exists(), run.stderr[-2000:]
    return out


def dump_dom(url: str, *args: str) -> str:
    """The DOM after the page's script ran (Chromium waits for the load)."""
    run = run_chromium(url, "--dump-dom", "--virtual-time-budget=5000", *args)
    assert run.stdout.strip(), run.stderr[-2000:]
    return run.stdout


def png_ink(path: Path) -> float:
    """The share of a screenshot's pixels that are not near-white (0: blank).
    An 8-bit RGB or RGBA PNG, as Chromium writes, unfiltered row by row."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, header = 8, b"", b""
    while pos < len(data):
        length = int.from_bytes(data[pos : pos + 4], "big")
        kind, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            header = body
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height = int.from_bytes(header[0:4], "big"), int.from_bytes(header[4:8], "big")
    assert header[8] == 8 and header[9] in (2, 6), "expected 8-bit RGB(A)"
    bpp = 3 if header[9] == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * bpp
    previous = bytearray(stride)
    inked = 0
    for row in range(height):
        start = row * (stride + 1)
        kind, line = raw[start], bytearray(raw[start + 1 : start + 1 + stride])
        if kind == 1:
            for i in range(bpp, stride):
                line[i] = (line[i] + line[i - bpp]) & 0xFF
        elif kind == 2:
            line = bytearray((a + b) & 0xFF for a, b in zip(line, previous, strict=True))
        elif kind == 3:
            for i in range(stride):
                left = line[i - bpp] if i >= bpp else 0
                line[i] = (line[i] + ((left + previous[i]) >> 1)) & 0xFF
        elif kind == 4:
            for i in range(stride):
                a = line[i - bpp] if i >= bpp else 0
                b, c = previous[i], previous[i - bpp] if i >= bpp else 0
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 0xFF
        inked += sum(1 for i in range(0, stride, bpp) if min(line[i : i + 3]) < 0xE0)
        previous = line
    return inked / (width * height)
