"""The linter's data model: plain, immutable values with no pxr and no I/O.

Formatters, the baseline and the Python API consume only these types, so they
never need a USD stage to exist.
"""

from __future__ import annotations

import enum
import re
from collections import Counter
from dataclasses import field
from inspect import cleandoc

from .records import record


class CorruptValue(Exception):
    """USD found a corrupt value in a layer while a rule read it (the file's
    problem, reported as ST001)."""


#: The renderer profiles (usdrender_lint.profiles, which a test keeps equal to
#: these), named here, below the layers that cannot import them: a rule's
#: ``profile`` (api.rule) and the configuration's JSON Schema (config).
PROFILE_NAMES = ("generic", "karma", "renderman", "arnold", "omniverse", "moonray", "cycles")


#: A property named "" (no layer parser writes one; a corrupt crate can hold it).
NAMELESS_PROPERTY = "the file holds a property with no name; the file is corrupt"


class Severity(enum.Enum):
    """How bad a finding is; ordered info < warning < error."""

    INFO = "info"
    WARNING = "warning"
    ERROR = "error"

    @property
    def rank(self) -> int:
        return _SEVERITY_RANK[self]

    @classmethod
    def parse(cls, text: str) -> Severity:
        try:
            return cls(text.strip().lower())
        except ValueError:
            allowed = ", ".join(s.value for s in cls)
            raise ValueError(f"unknown severity {text!r} (expected one of: {allowed})") from None

    def __str__(self) -> str:
        return self.value


_SEVERITY_RANK = {Severity.INFO: 0, Severity.WARNING: 1, Severity.ERROR: 2}

#: Reserved code for a rule that raised: reported, never selectable away.
INTERNAL_ERROR_CODE = "UL000"
INTERNAL_ERROR_NAME = "internal-error"
#: The customData key under which a prim lists the rules silenced on it.
IGNORE_KEY = "usdrender_lint:ignore"


@record(frozen=True)
class Location:
    """Where a finding is.

    ``file`` is the file that was linted (the stage's root layer as given),
    ``path`` the Sdf prim or property path (None for whole-file findings),
    ``layer`` the layer holding the strongest opinion behind the finding and
    ``line`` the line of that opinion when the layer is a text ``.usda``, and
    ``column`` its column where known (USD's parse errors give one).
    """

    file: str
    path: str | None = None
    layer: str | None = None
    line: int | None = None
    column: int | None = None


@record(frozen=True)
class FixInfo:
    """What an available automatic fix would do, and whether it is safe."""

    description: str
    safe: bool


@record(frozen=True)
class Finding:
    code: str
    name: str
    severity: Severity
    message: str
    location: Location
    fix: FixInfo | None = None
    #: The renderer profile the finding was judged under and why (R2-5);
    #: None for findings no profile judges (a file USD cannot open).
    profile: str | None = None
    profile_reason: str | None = None

    @property
    def variant_selection(self) -> str:
        """The variant selections ``--variants`` saw it under, when not the
        authored ones (engine/variants.py notes them in the message); else ''."""
        match = re.search(_VARIANT_SELECTION, self.message)
        return match.group(1) if match else ""

    def sort_key(self) -> tuple:
        return (
            self.location.file,
            self.location.path or "",
            self.code,
            self.message,
        )


#: The note ``--variants`` adds to the message of a finding seen only under
#: other variant selections than the authored ones.
VARIANT_SELECTION_NOTE = " [variant selection: {}]"
#: (Pattern text: re compiles it at first use, not at every start-up.)
_VARIANT_SELECTION = r"(?s) \[variant selection: (.*)\]\Z"


@record(frozen=True)
class FileResult:
    """The outcome for one input file.

    ``status`` is ``"linted"`` when the rules ran (a file USD cannot open is
    linted: it yields an ST001 finding) and ``"error"`` when the tool could not
    do its job for the file (it does not exist, timed out, ...).
    """

    file: str
    status: str = "linted"
    error: str | None = None
    findings: tuple[Finding, ...] = ()
    #: Lines for the user about this file beside its findings (e.g. how many
    #: variant combinations --variants skipped).
    notes: tuple[str, ...] = ()
    #: The configuration file the file was linted under (its nearest, the one
    #: --config names, the user's own); None: none, the defaults.
    config: str | None = None


#: The documentation site; it has one page per built-in rule (:func:`rule_doc_url`).
DOCS_URL = "https://usdrender-lint.readthedocs.io/en/latest/"


def rule_doc_url(code: str, name: str) -> str:
    """The address of a rule's page on the documentation site."""
    return f"{DOCS_URL}reference/rules/{code}-{name}/"


@record(frozen=True)
class RuleInfo:
    """A rule's metadata and documentation, for reports that describe rules."""

    code: str
    name: str
    severity: Severity
    summary: str
    doc: str
    fix: str = "none"
    #: Its page on the documentation site: a built-in rule's (and UL000's); None
    #: for a plugin's, which has none there.
    url: str | None = None


@record(frozen=True)
class AppliedFix:
    """A fix that --fix, --diff or --fix-to applied, or (with ``reason``) did not.

    ``layer`` is the layer it edits (or would edit): the one holding the
    strongest opinion behind the finding, or the --fix-to layer.
    """

    file: str
    code: str
    path: str | None
    layer: str | None
    description: str
    #: Why the fix was not applied; None when it was.
    reason: str | None = None

    @property
    def applied(self) -> bool:
        return self.reason is None

    def __str__(self) -> str:
        where = f" <{self.path}>" if self.path else ""
        text = f"{self.code}{where}: {self.description}"
        return text if self.applied else f"{text}: not applied: {self.reason}"


@record(frozen=True)
class Report:
    files: tuple[FileResult, ...] = ()
    #: The rules that ran (for formats that describe them, e.g. SARIF).
    rules: tuple[RuleInfo, ...] = ()
    #: Fixes applied by --fix (empty without it).
    applied_fixes: tuple[AppliedFix, ...] = field(default=())
    #: Fixes --fix selected but could not apply, each with its reason.
    unapplied_fixes: tuple[AppliedFix, ...] = field(default=())
    #: Rule codes whose fixes --fix never applies (config ``unfixable``).
    unfixable: frozenset[str] = frozenset()
    #: A run split by configuration: (file, its own ``unfixable``) of each file.
    unfixable_by_file: tuple[tuple[str, frozenset[str]], ...] = ()
    #: The severity the configuration gives a rule instead of its own (config
    #: ``severity``), by code: what its findings carry, and SARIF records.
    severities: tuple[tuple[str, Severity], ...] = ()
    #: A run split by configuration: (file, its own ``severities``) of each file.
    severities_by_file: tuple[tuple[str, tuple[tuple[str, Severity], ...]], ...] = ()
    #: Findings whose fix ``--fix`` leaves although they are new: the
    #: ``--baseline`` records another finding of their fingerprint (file, rule,
    #: place), and --fix changes no place the baseline accepts as it is.
    baseline_held: frozenset[Finding] = frozenset()

    def fixable(self, severity: Severity | None = None) -> tuple[int, int]:
        """Findings a ``--fix`` would fix, and how many more ``--unsafe-fixes``
        would: those whose fix is safe, and unsafe (``unfixable`` rules and
        ``baseline_held`` findings aside);
        of one ``severity`` only, when given."""
        fixes = [
            fix
            for result in self.files
            for f in result.findings
            if (fix := self.offered_fix(f, result.file)) is not None
            and severity in (None, f.severity)
        ]
        safe = sum(1 for fix in fixes if fix.safe)
        return safe, len(fixes) - safe

    def offered_fix(self, finding: Finding, file: str | None = None) -> FixInfo | None:
        """The fix this run offers for ``finding`` (linted in ``file``, by default
        its stage's): what every format shows as a fix and counts, so that they
        agree. None for a rule ``unfixable`` there and for a ``baseline_held``
        finding, whose fixes --fix leaves."""
        fix = finding.fix
        if fix is None or finding in self.baseline_held:
            return None
        if finding.code in self.unfixable_in(finding.location.file if file is None else file):
            return None
        return fix

    def unfixable_in(self, file: str) -> frozenset[str]:
        """The rule codes whose fixes ``--fix`` never applies in ``file``."""
        return dict(self.unfixable_by_file).get(file, self.unfixable)

    def unfixable_everywhere(self) -> frozenset[str]:
        """The rule codes whose fixes the run offers in no file: ``unfixable``
        in every file's configuration (a run split by configuration may make a
        rule unfixable in one part only, whose other files it still fixes)."""
        if not self.unfixable_by_file or not self.files:
            return self.unfixable
        return frozenset.intersection(*(self.unfixable_in(r.file) for r in self.files))

    @property
    def findings(self) -> tuple[Finding, ...]:
        return tuple(f for result in self.files for f in result.findings)

    @property
    def errored_files(self) -> tuple[FileResult, ...]:
        return tuple(r for r in self.files if r.status != "linted")

    def by_severity(self) -> dict[str, int]:
        counts = Counter(f.severity.value for f in self.findings)
        return {
            s.value: counts.get(s.value, 0)
            for s in (Severity.ERROR, Severity.WARNING, Severity.INFO)
        }

    def by_code(self) -> dict[str, int]:
        return dict(sorted(Counter(f.code for f in self.findings).items()))


#: The reserved internal-error code: no rule class (it cannot be selected or
#: ignored), but documented like one (``explain UL000``, SARIF's rule list).
INTERNAL_ERROR_RULE = RuleInfo(
    code=INTERNAL_ERROR_CODE,
    name=INTERNAL_ERROR_NAME,
    severity=Severity.ERROR,
    summary="A rule raised an exception on this file; its other findings on it are lost.",
    doc=cleandoc(
        """
        A rule raised an exception on this file; its other findings on it are lost.

        ## What it does
        Reports a rule that raised while checking the file: the finding names the
        rule, the exception, the prim it was checking and where in the rule's source
        it raised. The other rules' findings on the file are kept.

        ## Why is this bad?
        The rule did not check the file, and a gate must never pass a file a rule
        could not check: like ST001, this code cannot be selected away.

        ## What to do
        It is a bug in the rule, not in the file: report it to the rule's authors
        with the message and, if you can, the file. A value USD finds corrupt while
        a rule reads it is the file's problem and is reported as ST001 instead.

        ## Fix safety
        No automatic fix.
        """
    ),
    url=rule_doc_url(INTERNAL_ERROR_CODE, INTERNAL_ERROR_NAME),
)
