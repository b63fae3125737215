"""A file whose lint runs out of memory is one the tool could not lint (exit 2,
"out of memory"), never an ST001 finding blaming the file, and never a rule's UL000."""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest

from usdrender_lint.api import Context, Rule, Severity, schemas
from usdrender_lint.engine import Linter

pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_DATA"),
    pytest.mark.heavy(seconds=10),
]

SMALL = """#usda 1.0

def Scope "Render"
{
    def RenderSettings "Settings"
    {
    }
}
"""
#: What the command may allocate in the test: it starts in about 150 MiB; the big
#: layer's points need several hundred more to parse.
LIMIT = 320 << 20


def _big_layer(path: Path, points: int = 5_000_000) -> None:
    tuples = ", ".join(["(0, 0, 0)"] * points)
    path.write_text(
        f'#usda 1.0\n\ndef Mesh "m"\n{{\n    point3f[] points = [{tuples}]\n}}\n\n{SMALL[10:]}'
    )


def _limited() -> None:
    resource.setrlimit(resource.RLIMIT_DATA, (LIMIT, resource.getrlimit(resource.RLIMIT_DATA)[1]))


@pytest.mark.parametrize("how", [[], ["--timeout", "0"]], ids=["worker", "in-process"])
def test_a_file_usd_cannot_allocate_for_is_an_error_not_a_finding(
    tmp_path: Path, how: list[str]
) -> None:
    _big_layer(tmp_path / "big.usda")
    (tmp_path / "small.usda").write_text(SMALL)
    command = [sys.executable, "-m", "usdrender_lint", "check", "--isolated", "--no-cache"]
    done = subprocess.run(
        [*command, "--jobs", "1", *how, "--format", "json", "big.usda", "small.usda"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        preexec_fn=_limited,
        env={**os.environ, "USDRENDER_LINT_NO_CACHE": "1"},
        timeout=300,
    )
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    by_file = {f["file"]: f for f in json.loads(done.stdout)["files"]}
    big = by_file["big.usda"]
    assert big["status"] == "error"
    assert big["findings"] == []
    assert big["error"].startswith("big.usda: out of memory: reading the file needs more than")
    assert "MiB this process may allocate" in big["error"]
    # The next file is linted as ever.
    assert by_file["small.usda"]["status"] == "linted"
    assert done.stderr.count("out of memory") == 1


class Hungry(Rule):
    """Allocates more than there is.

    ## What it does
    Test rule.
    """

    code = "TST900"
    name = "hungry"
    severity = Severity.ERROR
    prim_types = (schemas.RenderSettings,)

    def check_prim(self, prim, ctx: Context):  # noqa: ANN001, ANN201
        raise MemoryError
        yield


def test_a_rule_that_runs_out_of_memory_fails_the_file_not_the_rule(tmp_path: Path) -> None:
    path = tmp_path / "small.usda"
    path.write_text(SMALL)
    result = Linter([Hungry()]).lint_path(str(path))
    assert result.status == "error"
    assert result.findings == ()
    assert result.error is not None and "out of memory" in result.error


@pytest.mark.parametrize(
    ("data", "space", "said"),
    [
        (None, None, "more memory than the machine could give"),
        (320 << 20, None, "more than the 320 MiB this process may allocate"),
        (21 << 30, 1100 << 20, "more than the address-space limit (ulimit -v) of 1.1 GiB allows"),
        (320 << 20, 2 << 30, "more than the 320 MiB this process may allocate"),
    ],
)
def test_the_out_of_memory_message_names_the_smaller_limit(
    monkeypatch: pytest.MonkeyPatch, data: int | None, space: int | None, said: str
) -> None:
    """Under ``ulimit -v`` 1.1 GiB a worker's file said it needed "more than the
    21.2 GiB this process may allocate" (its data cap), not the limit that ran out."""
    from usdrender_lint.engine.stage import out_of_memory_message

    limits = {
        resource.RLIMIT_DATA: resource.RLIM_INFINITY if data is None else data,
        resource.RLIMIT_AS: resource.RLIM_INFINITY if space is None else space,
    }
    monkeypatch.setattr(resource, "getrlimit", lambda which: (limits[which], limits[which]))
    assert said in out_of_memory_message()
