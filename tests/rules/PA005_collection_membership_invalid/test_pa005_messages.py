"""PA005 messages: USD's reason, stated once per collection."""

from __future__ import annotations

from pathlib import Path

from usdrender_lint.rules.passes.pa005_collection_membership_invalid import (
    CollectionMembershipInvalid,
)
from usdrender_lint.testing import lint

HERE = Path(__file__).parent


def _messages(name: str) -> list[str]:
    return [f.message for f in lint(HERE / name, [CollectionMembershipInvalid()])]


def test_evaluation_error_is_reported_once() -> None:
    # usd-core raises the same predicate error from Validate() and from
    # ComputeMembershipQuery(); the finding carries it once.
    (message,) = _messages("fail_from_sublayer.usda")
    assert message.count("No registered function 'isMesh'") == 1


def test_validate_and_reference_reasons() -> None:
    messages = " | ".join(
        _messages("fail_validate.usda") + _messages("fail_missing_reference.usda")
    )
    assert "Invalid expansionRule value 'expandEverything'" in messages
    assert "circular dependencies" in messages
    assert "references the collection </Render/self.collection:props>" in messages
