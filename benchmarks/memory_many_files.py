"""Memory over many files in one process: generate N small shot layers, lint
them one after another with the full rule set, and print the peak resident set
size after the first 100 files and after all N. Bounded memory means the two
figures stay close: no stage, layer or finding cache grows with the file count.

    .venv/bin/python benchmarks/memory_many_files.py [N]   (default 2000)

Not a timed test; the figures go into the issue's closing note.
"""

from __future__ import annotations

import argparse
import gc
import resource
import sys
import tempfile
import time
from pathlib import Path

from pxr import Sdf

from usdrender_lint.config import Settings
from usdrender_lint.running.pipeline import make_linter
from usdrender_lint.running.workers import lint_one

SHOT = """#usda 1.0
(
    renderSettingsPrimPath = "/Render/Settings"
)
def Scope "Render"
{{
    def RenderSettings "Settings"
    {{
        rel camera = </World/Cam{index}>
        rel products = </Render/Beauty>
        uniform int2 resolution = ({width}, 1080)
        uniform float4 dataWindowNDC = (0, 0, 1, {window})
    }}
    def RenderProduct "Beauty"
    {{
        token productName = "beauty.{index}.exr"
        rel orderedVars = [</Render/Vars/color>, </Render/Vars/depth>]
    }}
    def Scope "Vars"
    {{
        def RenderVar "color"
        {{
            uniform string sourceName = "Ci"
        }}
        def RenderVar "depth"
        {{
            uniform token dataType = "float"
            uniform string sourceName = "z"
        }}
    }}
}}
def Xform "World"
{{
    def Camera "Cam{index}"
    {{
        float focalLength = {focal}
        float2 clippingRange = (0.1, 10000)
    }}
}}
"""


def peak_rss_mib() -> float:
    # Linux reports ru_maxrss in KiB (macOS in bytes).
    scale = 1 / 1024 if sys.platform != "darwin" else 1 / (1024 * 1024)
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * scale


def current_rss_mib() -> float | None:
    try:
        pages = int(Path("/proc/self/statm").read_text().split()[1])
    except OSError:
        return None
    return pages * resource.getpagesize() / (1024 * 1024)


def write_files(folder: Path, count: int) -> list[str]:
    paths = []
    for index in range(count):
        path = folder / f"shot_{index:05d}.usda"
        if index % 50 == 49:
            path.write_text('#usda 1.0\ndef Scope "Broken" {\n')  # an ST001 now and then
        else:
            path.write_text(
                SHOT.format(
                    index=index,
                    width=1920 + index % 7,
                    window=1 if index % 3 else 0,  # a third get SE003
                    focal=35 + index % 11,
                )
            )
        paths.append(str(path))
    return paths


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("count", nargs="?", type=int, default=2000)
    args = parser.parse_args(argv)
    count = max(args.count, 101)
    linter = make_linter(Settings())
    with tempfile.TemporaryDirectory() as folder:
        paths = write_files(Path(folder), count)
        findings = 0
        started = time.perf_counter()
        for done, path in enumerate(paths, start=1):
            findings += len(lint_one(linter, path).findings)
            if done in (100, count):
                gc.collect()
                open_layers = len(Sdf.Layer.GetLoadedLayers())
                print(
                    f"after {done:>6} files: peak RSS {peak_rss_mib():7.1f} MiB, "
                    f"current {current_rss_mib() or float('nan'):7.1f} MiB, "
                    f"layers still loaded {open_layers}, findings {findings}, "
                    f"{time.perf_counter() - started:6.1f} s"
                )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
