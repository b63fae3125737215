"""Rule discovery and selection.

Built-in rules and third-party rules register the same way: an entry point in
the ``usdrender_lint.rules`` group naming a sequence of :class:`Rule` classes.
A plugin that fails to load or a duplicate code is an error, never a log line:
a CI gate must not silently lose rules.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from . import entrypoints
from .api import Rule
from .api.rule import profile_problem
from .records import record

ENTRY_POINT_GROUP = "usdrender_lint.rules"


class RegistryError(Exception):
    """A rule plugin could not be loaded or conflicts with another."""


@record(frozen=True)
class Registry:
    rules: tuple[type[Rule], ...]
    #: Which entry point (plugin) provided each rule code.
    origins: dict[str, str]

    def by_code(self, code: str) -> type[Rule]:
        for rule in self.rules:
            if rule.code == code:
                return rule
        raise KeyError(code)

    def find(self, code_or_name: str) -> type[Rule] | None:
        key = code_or_name.strip()
        for rule in self.rules:
            if key.upper() == rule.code or key.lower() == rule.name or key in _aliases(rule):
                return rule
        return None

    def plugins(self) -> set[str]:
        return set(self.origins.values())

    def nearest(self, code_or_name: str, also: Iterable[str] = ()) -> str | None:
        """The rule code or name closest to a mistyped one (``camera_unset``,
        ``CA01``), for a "did you mean"; None when none is close. ``also``:
        more codes and names to consider (ones no rule class has)."""
        import difflib

        def fold(word: str) -> str:
            return word.strip().lower().replace("_", "-")

        words = [word for rule in self.rules for word in (rule.code, rule.name)]
        folded = {fold(word): word for word in [*words, *also]}
        close = difflib.get_close_matches(fold(code_or_name), folded, n=1, cutoff=0.75)
        return folded[close[0]] if close else None


def _aliases(rule: type[Rule]) -> tuple[str, ...]:
    return tuple(getattr(rule, "aliases", ()))


def build_registry(
    entry_points: Iterable[entrypoints.EntryPointLike] | None = None,
) -> Registry:
    """Load every rule plugin; raise :class:`RegistryError` on any problem."""
    if entry_points is None:
        entry_points = entrypoints.entry_points(ENTRY_POINT_GROUP)
    rules: list[type[Rule]] = []
    origins: dict[str, str] = {}
    #: Each code's plugin as the errors name it: two plugins may share an entry point name.
    providers: dict[str, str] = {}
    #: Every name and alias (selectors and suppressions read both) -> the code it names.
    names: dict[str, str] = {}
    for ep in sorted(entry_points, key=lambda e: (e.name != "builtin", e.name)):
        try:
            loaded = ep.load()
        except Exception as exc:
            raise RegistryError(
                f"rule plugin {ep.name!r} ({ep.value}) failed to load: {type(exc).__name__}: {exc}"
            ) from exc
        if isinstance(loaded, type):
            loaded = [loaded]
        try:
            classes = list(loaded)
        except TypeError:
            raise RegistryError(
                f"rule plugin {ep.name!r} ({ep.value}) must name a sequence of Rule classes"
            ) from None
        for cls in classes:
            if not (isinstance(cls, type) and issubclass(cls, Rule)):
                raise RegistryError(
                    f"rule plugin {ep.name!r} provides {cls!r}, which is not a Rule subclass"
                )
            if cls.abstract:
                raise RegistryError(
                    f"rule plugin {ep.name!r} provides {cls.__qualname__}, an abstract base "
                    "class (abstract = True), not a rule"
                )
            provider = f"plugin {ep.name!r} ({ep.value})"
            if (problem := profile_problem(cls.profile)) is not None:
                # Set after the class was defined (its own check saw a valid one).
                raise RegistryError(
                    f"rule {cls.code} ({cls.__qualname__}) of {provider}: {problem}"
                )
            if cls.code in origins:
                raise RegistryError(
                    f"duplicate rule code {cls.code}: provided by {providers[cls.code]} "
                    f"and by {provider}"
                )
            for word in dict.fromkeys((cls.name, *_aliases(cls))):
                if word in names:
                    other = names[word]
                    raise RegistryError(
                        f"duplicate rule name {word!r}: {other} of {providers[other]} and "
                        f"{cls.code} of {provider} (names and aliases must be unique)"
                    )
                names[word] = cls.code
            origins[cls.code] = ep.name
            providers[cls.code] = provider
            rules.append(cls)
    if not rules:
        raise RegistryError(
            f"no rules are registered in entry point group {ENTRY_POINT_GROUP!r}; "
            "is usdrender-lint installed (pip install .)?"
        )
    return Registry(tuple(sorted(rules, key=lambda r: r.code)), origins)


class SelectionError(ValueError):
    """A selector names no rule."""


def _specificity(selector: str, rule: type[Rule]) -> int:
    """How specifically ``selector`` matches ``rule``: 0 = no match.

    Names and aliases are as specific as a full code; a code prefix counts its
    length ("ALL" matches everything, least specifically).
    """
    token = selector.strip()
    if not token:  # a prefix of every code, but it names none: not ALL in disguise
        return 0
    if token.upper() == "ALL":
        return 1
    if token.lower() == rule.name or token in _aliases(rule):
        return 1000
    if rule.code.startswith(token.upper()):
        return 1 + len(token)
    return 0


def select_rules(
    rules: Sequence[type[Rule]],
    select: Sequence[str] | None = None,
    ignore: Sequence[str] = (),
    extend_select: Sequence[str] = (),
    below: Sequence[tuple[Sequence[str] | None, Sequence[str], Sequence[str]]] = (),
) -> list[type[Rule]]:
    """Which rules run. ``select`` None means all. The most specific matching
    selector decides (an ignore wins a tie), as in ruff. ``below``: the
    ``(select, ignore, extend_select)`` of the layers under this one (files
    extended, the file under the flags), first to last: as ruff layers them,
    each starts from what the one before chose, a ``select`` of its own
    starting over, so that ``--select CA`` runs CA where the file ignores it
    and ``--ignore`` adds to the file's ``ignore``."""
    layers = [*below, (select, ignore, extend_select)]
    for layer_select, layer_ignore, layer_extend in layers:
        for token in [*(layer_select or ()), *layer_extend, *layer_ignore]:
            if not any(_specificity(token, r) for r in rules):
                raise SelectionError(f"{token!r} matches no rule code, code prefix or rule name")
    chosen = set(rules)  # the defaults: every rule
    for layer_select, layer_ignore, layer_extend in layers:
        selectors = [*(layer_select or ()), *layer_extend]
        if layer_select is not None:
            chosen = set()
        for rule in rules:
            best_select = max((_specificity(t, rule) for t in selectors), default=0)
            best_ignore = max((_specificity(t, rule) for t in layer_ignore), default=0)
            if best_select > best_ignore:
                chosen.add(rule)
            elif best_ignore:
                chosen.discard(rule)
    return [rule for rule in rules if rule in chosen]


def matches_any(rule: type[Rule], selectors: Iterable[str]) -> bool:
    """True when a code, prefix or name in ``selectors`` names ``rule``."""
    return any(_specificity(token, rule) for token in selectors)
