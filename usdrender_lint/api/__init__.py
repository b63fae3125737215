"""The rule-author API: everything a rule, built-in or third-party, needs.

``from usdrender_lint.api import Context, Diagnostic, Fix, Rule, Severity, schemas``;
:mod:`usdrender_lint.api.resolve` holds the USD resolution every rule shares.
``record`` is ``@dataclass`` without its import-time cost (usdrender_lint.records),
for a rule's ``Options`` and helpers.
"""

from __future__ import annotations

from ..model import Severity
from ..records import record
from . import schemas
from .context import Context, FullStageRequired
from .rule import DOC_SECTIONS, Diagnostic, Fix, Rule

__all__ = [
    "DOC_SECTIONS",
    "Context",
    "Diagnostic",
    "Fix",
    "FullStageRequired",
    "Rule",
    "Severity",
    "record",
    "schemas",
]
