"""The real public USD files in ../shared/corpus lint without a crash: every
file is linted (findings or none) or gives ST001, and no rule raises (UL000)."""

from __future__ import annotations

from pathlib import Path

from usdrender_lint.engine import STAGE_OPEN_FAILED_CODE, Linter
from usdrender_lint.model import INTERNAL_ERROR_CODE
from usdrender_lint.running.discovery import collect_files
from usdrender_lint.testing import all_rules


def test_corpus_lints_without_internal_errors(shared_dir: Path) -> None:
    files = collect_files([str(shared_dir / "corpus" / "files")])
    assert files, "the corpus has no USD files"
    linter = Linter(all_rules())
    crashed: dict[str, list[str]] = {}
    not_linted: dict[str, str | None] = {}
    opened = 0
    for path in files:
        result = linter.lint_path(path)
        if result.status != "linted":
            not_linted[path] = result.error
            continue
        codes = {f.code for f in result.findings}
        opened += STAGE_OPEN_FAILED_CODE not in codes
        internal = [f.message for f in result.findings if f.code == INTERNAL_ERROR_CODE]
        if internal:
            crashed[path] = internal
    assert not crashed, f"rules raised on corpus files: {crashed}"
    assert not not_linted, f"files neither linted nor reported as ST001: {not_linted}"
    # Most of the corpus is valid USD: ST001 on everything would hide a broken open.
    assert opened > len(files) // 2
