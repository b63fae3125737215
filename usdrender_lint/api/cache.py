"""The per-lint cache: answers that rules and resolution helpers share while
one stage is linted, dropped with the lint.

Every answer is keyed by the function that computes it and its arguments, so
two helpers can never collide on a key and a key never needs spelling out.
The stage must not be edited while its cache is active: the engine runs every
rule before any fix is applied, and each lint (the fixer's second one, a nested
one) has a cache of its own. Process-wide caches are kept only for pure facts
(schema definitions, parsed expressions), never for anything a stage holds.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any, TypeVar

_T = TypeVar("_T")
#: "Not computed yet" (None is a remembered answer).
_MISSING: Any = object()


class LintCache:
    """Answers of ``func(*args)``, computed once per lint."""

    __slots__ = ("_answers", "by_identity", "without_clips", "without_varying")

    def __init__(self, without_clips: bool = False, without_varying: bool = False) -> None:
        self._answers: dict[tuple[Callable[..., Any], tuple[Hashable, ...]], Any] = {}
        #: Answers keyed by an object's ``id``: for USD handles, whose hash is
        #: a binding call (resolve.PrimValues). Whoever adds an entry keeps the
        #: object alive until the lint ends, so that its id is not reused.
        self.by_identity: dict[int, Any] = {}
        #: True when no layer of the linted stage can author value clips (the
        #: engine knows from the layers' words). Then an attribute holds an
        #: authored value only if its prim's authored property names list it:
        #: a clip gives values to attributes that no layer's spec names.
        self.without_clips = without_clips
        #: True when no layer of the linted stage can author time samples or a
        #: spline (neither field's word is in any): then no spec holds either,
        #: known without asking each spec.
        self.without_varying = without_varying

    @property
    def nothing_varies(self) -> bool:
        """No attribute of the linted stage can vary: no layer can author time
        samples, a spline or value clips (``PrimValues.may_vary`` is then False
        for every name)."""
        return self.without_clips and self.without_varying

    def call(self, func: Callable[..., _T], *args: Hashable) -> _T:
        """``func(*args)``, computed on the first call with these arguments."""
        key = (func, args)
        # One lookup on a hit: keys hold USD objects, whose hashing is not free.
        answer = self._answers.get(key, _MISSING)
        if answer is _MISSING:
            answer = self._answers[key] = func(*args)
        return answer

    def put(self, func: Callable[..., _T], args: tuple[Hashable, ...], answer: _T) -> None:
        """Make ``func(*args)`` answer ``answer`` for the rest of the lint: for a
        caller that knows better than ``func`` would read (a layer's unsaved
        text in an editor, where its file holds an older one)."""
        self._answers[(func, args)] = answer

    def __len__(self) -> int:
        return len(self._answers)


#: The cache of the lint running in this thread (None outside a lint), for the
#: helpers that are called without a Context (resolution, line lookup).
_ACTIVE: ContextVar[LintCache | None] = ContextVar("usdrender_lint_cache", default=None)


def active_cache() -> LintCache | None:
    return _ACTIVE.get()


@contextmanager
def lint_cache(cache: LintCache | None = None) -> Iterator[LintCache]:
    """Make ``cache`` (a new one by default) the active cache until the block ends."""
    cache = cache if cache is not None else LintCache()
    token = _ACTIVE.set(cache)
    try:
        yield cache
    finally:
        _ACTIVE.reset(token)


def cached(func: Callable[..., _T]) -> Callable[..., _T]:
    """``func`` answering from the active lint's cache; a plain call outside a lint."""

    def call(*args: Hashable) -> _T:
        cache = _ACTIVE.get()
        if cache is None:
            return func(*args)
        # LintCache.call inlined: a thousand calls a shot on a CI gate.
        answers = cache._answers
        key = (func, args)
        answer = answers.get(key, _MISSING)
        if answer is _MISSING:
            answer = answers[key] = func(*args)
        return answer

    call.__wrapped__ = func  # type: ignore[attr-defined]
    call.__name__ = func.__name__
    call.__qualname__ = func.__qualname__
    call.__doc__ = func.__doc__
    return call
