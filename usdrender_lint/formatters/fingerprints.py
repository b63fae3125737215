"""The identity of a finding across runs, for the CI reports that track
findings from one commit to the next: GitLab Code Quality's ``fingerprint``
and SARIF's ``partialFingerprints`` carry the same value.

A SHA-256 of the rule code, the linted file and the layer holding the opinion
(both relative to the folder the report names files from: the same on every
checkout), the prim or property path and the message, with the
occurrence index of an identical finding. The line is left out, so an edit
above a finding does not make it new.
"""

from __future__ import annotations

import hashlib

from ..model import Finding
from ..paths import display_path, layer_file


def fingerprint(*parts: str, occurrence: int = 0) -> str:
    """A SHA-256 hex digest of ``parts`` and the occurrence index. A lone
    surrogate (a byte of a name that is not UTF-8) is hashed as its code
    point: the same on every run, and never an error."""
    key = "\0".join((*parts, str(occurrence)))
    return hashlib.sha256(key.encode("utf-8", "surrogatepass")).hexdigest()


def finding_key(finding: Finding, base: str | None = None) -> tuple[str, ...]:
    """What tells findings apart: code, stage, layer (the files relative to
    ``base``, by default the working directory), prim path and message."""
    loc = finding.location
    layer = display_path(str(layer_file(loc.layer) or loc.file), base)
    return (finding.code, display_path(loc.file, base), layer, loc.path or "", finding.message)


class Occurrences:
    """How many times each key came before: two identical findings (the same
    key) get different fingerprints by it, and the same ones on every run."""

    def __init__(self, base: str | None = None) -> None:
        #: The folder the fingerprinted paths are relative to (None: the working directory).
        self.base = base
        self._seen: dict[tuple[str, ...], int] = {}

    def __call__(self, key: tuple[str, ...]) -> int:
        count = self._seen.get(key, 0)
        self._seen[key] = count + 1
        return count

    def fingerprint(self, finding: Finding) -> str:
        """The finding's fingerprint, counting it as one more occurrence."""
        key = finding_key(finding, self.base)
        return fingerprint(*key, occurrence=self(key))
