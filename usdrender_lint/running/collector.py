"""Python's cyclic garbage collector in the command's own processes, which lint.

A lint makes no reference cycles (the engine breaks its own at the end of each
lint: tests/engine/test_reference_cycles.py), so what it makes dies by reference
counting and a collection during a lint finds nothing to free. Python's default
collects its youngest generation after 700 net allocations; a CI-gate shot
makes more than that, so each shot paid one collection that walked the lint's
live objects and freed nothing: 1.01 collections and 0.09 ms of a 5.3 ms shot,
and the shots ran 2.6% faster without them (benchmarks/run.py --only collector).
After LINT_THRESHOLD allocations, 500 gate shots in a row paid none, and the
collector still runs for the cycles a plugin's rule may make.

Only the command line's processes are set so, once they import the engine
(cli/loading.import_engine: ``check``, ``spec``, ``merge``, ``rules``...), and
their pool workers: a host's process (the Python API, the UsdValidation plugin)
keeps its collector as its owner set it, and so does the language server's
child, whose lints are of one document at a time.
"""

from __future__ import annotations

import gc

#: Net allocations between two collections of the youngest generation.
LINT_THRESHOLD = 50_000


def collect_less_often() -> None:
    """Collect the youngest generation after LINT_THRESHOLD allocations, unless
    the collector is off (a threshold of 0) or already collects less often."""
    youngest, *older = gc.get_threshold()
    if 0 < youngest < LINT_THRESHOLD:
        gc.set_threshold(LINT_THRESHOLD, *older)
