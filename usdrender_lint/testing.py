"""Fixture harness for rule tests, shipped for plugin authors too.

A rule's fixture folder holds ``pass_*.usda`` files, which must give no finding
of the rule, and ``fail_*.usda`` files, which list the findings they expect on
comment lines (USD ignores them), usually right after the header::

    #usda 1.0
    # expect: CA004 </Render/Settings.camera> x1 fix "is an Xform, not a Camera"
    # expect: SE003 </Render/S.dataWindowNDC> x2 nofix "xmin"

One line, in this order: ``# expect:``, the rule code, the prim or property
path in angle brackets (``<>`` for a whole-stage finding), then, each optional:

- ``xN``: how many findings of the code at that path match the line (default 1);
- ``fix`` or ``nofix``: whether each of them offers an automatic fix;
- ``"fragment"``: text that must occur in each message; it runs to the last
  double quote on the line, so it may itself hold quotes (no escapes).

A fail fixture gives exactly the findings of its code that its lines declare:
each line matches exactly N findings, and every finding of the code matches one
line. Two lines on the same path need fragments (or fix states) that tell their
findings apart. A line that starts with ``# expect:`` but does not parse is an
error, never silently skipped.

Any other file in the folder is a supporting layer (a sublayer or a reference).

:func:`lint_text` lints usda text (with supporting layers by file name) without
the caller writing files.
"""

from __future__ import annotations

import dataclasses
import os
import re
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path, PurePosixPath
from typing import Any

from .api import Rule
from .api.rule import profile_problem
from .engine import Linter
from .model import Finding, Location
from .records import record
from .registry import Registry, build_registry, select_rules

_EXPECT_PREFIX = re.compile(r"^#\s*expect:")
_EXPECT = re.compile(
    r"^#\s*expect:\s*(?P<code>[A-Z]+[0-9]+)\s+<(?P<path>[^>]*)>"
    r"(?:\s+x(?P<count>[1-9][0-9]*))?"
    r"(?:\s+(?P<fix>fix|nofix))?"
    r'(?:\s+"(?P<fragment>.*)")?\s*$'
)


@record(frozen=True)
class Expectation:
    """One ``# expect:`` line of a fail fixture; None: not stated (not checked)."""

    code: str
    path: str
    count: int | None = None
    fix: bool | None = None
    fragment: str | None = None
    line: int = 0

    @property
    def full(self) -> bool:
        """The line states count, fix and fragment."""
        return None not in (self.count, self.fix, self.fragment)

    def matches(self, finding: Finding) -> bool:
        return (
            finding.code == self.code
            and (finding.location.path or "") == self.path
            and (self.fix is None or (finding.fix is not None) == self.fix)
            and (self.fragment is None or self.fragment in finding.message)
        )

    def __str__(self) -> str:
        parts = [f"{self.code} <{self.path}> x{self.count or 1}"]
        if self.fix is not None:
            parts.append("fix" if self.fix else "nofix")
        if self.fragment is not None:
            parts.append(f'"{self.fragment}"')
        return " ".join(parts)


class ExpectationError(ValueError):
    """A ``# expect:`` line that does not parse."""


def expectations(path: str | Path) -> list[Expectation]:
    """The expectations a fail fixture declares, in file order."""
    path = Path(path)
    found = []
    for number, raw in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        line = raw.strip()
        if number == 1 or not _EXPECT_PREFIX.match(line):
            continue
        match = _EXPECT.match(line)
        if match is None:
            raise ExpectationError(
                f"{path.name}:{number}: cannot read {line!r}; expected "
                "'# expect: CODE <path> [xN] [fix|nofix] [\"message fragment\"]'"
            )
        count, fix = match.group("count"), match.group("fix")
        found.append(
            Expectation(
                code=match.group("code"),
                path=match.group("path"),
                count=int(count) if count else None,
                fix=None if fix is None else fix == "fix",
                fragment=match.group("fragment"),
                line=number,
            )
        )
    return found


def all_rules() -> list[Rule]:
    return [rule() for rule in build_registry().rules]


def lint(
    path: str | Path, rules: Sequence[Rule] | None = None, profiler: Any = None
) -> list[Finding]:
    """Lint a file with every registered rule; a rule that raises fails the test.
    ``profiler`` judges findings under renderer profiles as ``check`` does
    (``usdrender_lint.profiles.Profiler()``); without one, the schema alone and
    no renderer rule runs."""
    linter = Linter(
        rules if rules is not None else all_rules(), raise_errors=True, profiler=profiler
    )
    result = linter.lint_path(str(path))
    assert result.status == "linted", result.error
    return list(result.findings)


def _chosen(rules: Sequence[Rule] | None, select: Sequence[str] | None) -> list[Rule]:
    chosen = list(rules) if rules is not None else all_rules()
    if select is None:
        return chosen
    kept = set(select_rules([type(rule) for rule in chosen], select))
    return [rule for rule in chosen if type(rule) in kept]


def _layer_file(folder: Path, name: str) -> Path:
    relative = PurePosixPath(name)
    if relative.is_absolute() or ".." in relative.parts or not relative.parts:
        raise ValueError(f"layer name {name!r} must be a relative path inside the stage's folder")
    return folder.joinpath(*relative.parts)


def _relative(finding: Finding, folder: str) -> Finding:
    """The finding with paths inside ``folder`` (gone after the lint) relative to it."""
    prefix = folder + os.sep

    def strip(text: str | None) -> str | None:
        return None if text is None else text.replace(prefix, "")

    location = finding.location
    relative = Location(
        file=strip(location.file) or "",
        path=location.path,
        layer=strip(location.layer),
        line=location.line,
    )
    return dataclasses.replace(finding, message=strip(finding.message) or "", location=relative)


def lint_text(
    usda: str,
    *,
    rules: Sequence[Rule] | None = None,
    select: Sequence[str] | None = None,
    layers: Mapping[str, str] | None = None,
    name: str = "stage.usda",
    profiler: Any = None,
) -> list[Finding]:
    """Lint ``usda`` (a whole layer, header included) as the file ``name``.

    ``rules`` are the rule instances to run (default: every registered rule,
    with default options); ``select`` narrows them by code, prefix or name as
    ``--select`` does (a selector matching none of them raises SelectionError).
    ``layers`` maps relative file names to the text of the supporting layers
    the stage's sublayers, references and payloads name (``@./lighting.usda@``).
    The files live in a temporary folder for the lint only: in the findings,
    files, layers and messages name them relative to it (``stage.usda``,
    ``lighting.usda``). A rule that raises fails the test.
    """
    if layers and name in layers:
        raise ValueError(f"{name!r} is the stage itself; give its supporting layers other names")
    chosen = _chosen(rules, select)
    # As with --select: a suppression naming a rule that is not run is not "unknown".
    known = [*build_registry().rules, *(type(rule) for rule in chosen)]
    linter = Linter(
        chosen, raise_errors=True, known_rules=list(dict.fromkeys(known)), profiler=profiler
    )
    with tempfile.TemporaryDirectory(prefix="usdrender-lint-") as tmp:
        folder = Path(os.path.realpath(tmp))
        for layer_name, text in {**(layers or {}), name: usda}.items():
            path = _layer_file(folder, layer_name)
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text, encoding="utf-8")
        result = linter.lint_path(str(_layer_file(folder, name)))
        assert result.status == "linted", result.error
    return [_relative(finding, str(folder)) for finding in result.findings]


def found_pairs(findings: Sequence[Finding], code: str) -> set[tuple[str, str]]:
    return {(f.code, f.location.path or "") for f in findings if f.code == code}


def fixture_files(folder: str | Path) -> list[Path]:
    folder = Path(folder)
    return sorted(
        p
        for p in folder.glob("*.usda")
        if p.name.startswith(("pass_", "fail_")) and not p.name.endswith(".fixed.usda")
    )


def _describe(findings: Sequence[Finding]) -> str:
    if not findings:
        return "none"
    return "; ".join(
        f"<{f.location.path or ''}> {'fix' if f.fix else 'nofix'} {f.message!r}" for f in findings
    )


def check_fixture(
    path: str | Path, code: str, rules: Sequence[Rule] | None = None, profiler: Any = None
) -> None:
    """Assert a fixture behaves: pass files give no ``code`` finding, fail files
    give exactly the findings of ``code`` their ``# expect:`` lines declare
    (count, fix offered and message fragment as stated). Without ``rules``, the
    built-in rules and those of ``code``'s plugin run (another plugin's rule
    that raises is not this fixture's failure). A ``code`` that none of the
    rules run has raises ValueError."""
    path = Path(path)
    chosen = _fixture_rules(code) if rules is None else rules
    if not any(rule.code == code for rule in chosen):
        # A mistyped code (or a plugin not installed) let every pass fixture pass.
        raise ValueError(_no_rule(code, chosen))
    _check_rule_profile(code, chosen, profiler)
    found = [f for f in lint(path, chosen, profiler) if f.code == code]
    if path.name.startswith("pass_"):
        assert not found, f"{path.name}: expected no {code} finding, got {_describe(found)}"
        return
    expected = [e for e in expectations(path) if e.code == code]
    assert expected, f"{path.name}: a fail fixture must declare '# expect: {code} <path> ...'"
    _check_expected(path, code, found, expected)
    _check_fix_safety(path, code, found, chosen)


def _check_fix_safety(
    path: Path, code: str, found: Sequence[Finding], rules: Sequence[Rule]
) -> None:
    """The fixes offered agree with the rule's ``fix_safety``, which ``rules``
    and ``explain`` show: a rule left at "none" that offers fixes was listed as
    having none."""
    safety = next(type(rule).fix_safety for rule in rules if rule.code == code)
    offered = [f for f in found if f.fix is not None]
    if safety == "none":
        assert not offered, (
            f"{path.name}: {code} offers fixes ({_describe(offered)}) but its fix_safety is "
            "'none'; set it to 'safe', 'safe-conditional' or 'unsafe'"
        )
        return
    if safety == "safe-conditional":
        return  # safe where it can tell, unsafe elsewhere
    wrong = [f for f in offered if f.fix is not None and f.fix.safe != (safety == "safe")]
    assert not wrong, (
        f"{path.name}: {code}'s fix_safety is {safety!r} but it offers "
        f"{'safe' if safety == 'unsafe' else 'unsafe'} fixes: {_describe(wrong)}"
    )


def _check_rule_profile(code: str, rules: Sequence[Rule], profiler: Any) -> None:
    """A renderer rule runs only where its profile is judged present: under a
    profile that does not exist, or with no ``profiler``, never, and every pass
    fixture of it passed while testing nothing."""
    rule = next(rule for rule in rules if rule.code == code)
    problem = profile_problem(rule.profile)
    if problem is not None:
        raise ValueError(f"{code} ({type(rule).__qualname__}): {problem}")
    if rule.profile is not None and profiler is None:
        raise ValueError(
            f"{code} is a rule of the {rule.profile} profile, which runs only where a "
            "profiler judges that profile present: pass "
            "profiler=usdrender_lint.profiles.Profiler()"
        )


def _no_rule(code: str, rules: Sequence[Rule]) -> str:
    """Why ``check_fixture`` cannot test ``code``: no rule it runs has it."""
    registry = Registry(tuple(type(rule) for rule in rules), {})
    found = registry.find(code)
    if found is not None:
        return f"{code!r} is the name of {found.code}; check_fixture takes a rule code"
    near = registry.nearest(code)
    hint = f" (did you mean {near}?)" if near else " (is its plugin installed?)"
    return f"no rule has code {code!r}{hint}"


def _fixture_rules(code: str) -> list[Rule]:
    """The rules a fixture of ``code`` runs: the built-in ones and those of the
    package ``code``'s rule is in (a rule that raises fails the test), not every
    installed plugin's, whose bugs are not the fixture's."""
    rules = build_registry().rules
    packages = {rule.__module__.partition(".")[0] for rule in rules if rule.code == code}
    return [
        rule()
        for rule in rules
        if rule.__module__.startswith("usdrender_lint.")
        or rule.__module__.partition(".")[0] in packages
    ]


def _check_count(path: Path, code: str, found: Sequence[Finding], expectation: Expectation) -> None:
    matching = [f for f in found if expectation.matches(f)]
    at_path = [f for f in found if (f.location.path or "") == expectation.path]
    assert len(matching) == (expectation.count or 1), (
        f"{path.name}:{expectation.line}: expected {expectation}, "
        f"got {len(matching)} matching; {code} findings at <{expectation.path}>: "
        f"{_describe(at_path)}"
    )


def _check_expected(
    path: Path, code: str, found: Sequence[Finding], expected: Sequence[Expectation]
) -> None:
    """Each expect line matches its count of findings, and each finding one line."""
    for expectation in expected:
        _check_count(path, code, found, expectation)
    unexpected = [f for f in found if not any(e.matches(f) for e in expected)]
    assert not unexpected, f"{path.name}: unexpected {code} findings: {_describe(unexpected)}"
    claimed = sum(e.count or 1 for e in expected)
    assert claimed == len(found), (
        f"{path.name}: the expect lines claim {claimed} {code} findings but {len(found)} "
        "occur: two lines match the same finding; make their fragments tell them apart"
    )
