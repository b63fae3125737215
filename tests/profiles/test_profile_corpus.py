"""No loss of recall on real content (issue 15, point 5): on every file of
../shared/corpus, what ``auto`` reports differs from ``generic`` only where a
renderer profile says its renderer does not act on the condition (R2-5)."""

from __future__ import annotations

from pathlib import Path

from usdrender_lint.engine import Linter
from usdrender_lint.profiles import PROFILES, Profiler
from usdrender_lint.profiles.effective import ACCEPTED_BY_RULE
from usdrender_lint.running.discovery import collect_files
from usdrender_lint.testing import all_rules

#: The generic rules a profile may drop a finding of: its rule changes and the
#: rules that read its accepted cameras, types, product types and var outputs.
PROFILE_AWARE = {c.code for p in PROFILES.values() for c in p.changes} | set(ACCEPTED_BY_RULE)


def test_auto_keeps_every_generic_finding_its_renderer_acts_on(shared_dir: Path) -> None:
    rules = all_rules()
    auto = Linter(rules, profiler=Profiler())
    generic = Linter(rules, profiler=Profiler(lambda f: ("generic", "test")))
    dropped: dict[str, set[tuple[str, str | None]]] = {}
    for path in collect_files([str(shared_dir / "corpus" / "files")]):
        by_generic = {(f.code, f.location.path) for f in generic.lint_path(path).findings}
        found = auto.lint_path(path).findings
        by_auto = {(f.code, f.location.path) for f in found}
        lost = by_generic - by_auto
        assert {code for code, _ in lost} <= PROFILE_AWARE, (path, lost)
        if lost:
            # Only where a renderer profile judged the file.
            assert {f.profile for f in found} - {"generic"}, (path, lost)
            dropped[path] = lost
    # The profiles do act on the corpus's Omniverse stages (Kit viewport products).
    assert any("NVIDIA-Omniverse" in path for path in dropped)
