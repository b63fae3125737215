"""What the fast entry point reader (usdrender_lint/entrypoints.py) saves at
start-up against importlib.metadata, each in a fresh interpreter (the two
groups every `check` reads: rules and formatters).

    python benchmarks/entry_points.py [--rounds N]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys

GROUPS = ("usdrender_lint.rules", "usdrender_lint.formatters")
FAST = "from usdrender_lint import entrypoints as e\n" + "".join(
    f"e.entry_points({group!r})\n" for group in GROUPS
)
LIBRARY = "from importlib import metadata as m\n" + "".join(
    f"m.entry_points(group={group!r})\n" for group in GROUPS
)
TIMED = "import time\nt = time.perf_counter()\n{body}print(time.perf_counter() - t)\n"


def _seconds(body: str) -> float:
    done = subprocess.run(
        [sys.executable, "-c", TIMED.format(body=body)], capture_output=True, text=True, check=True
    )
    return float(done.stdout)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--rounds", type=int, default=9)
    rounds = parser.parse_args().rounds
    fast = statistics.median(_seconds(FAST) for _ in range(rounds))
    library = statistics.median(_seconds(LIBRARY) for _ in range(rounds))
    print(f"entry points, fast reader:      {fast * 1000:7.1f} ms (median of {rounds})")
    print(f"entry points, importlib.metadata: {library * 1000:5.1f} ms")
    print(f"fast / importlib.metadata:       {fast / library:7.2f}x")


if __name__ == "__main__":
    main()
