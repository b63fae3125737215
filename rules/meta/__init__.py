"""UL: checks on the linter's own markup in the data (suppressions)."""

from __future__ import annotations

from .ul001_unused_suppression import UnusedSuppression

RULES = (UnusedSuppression,)
