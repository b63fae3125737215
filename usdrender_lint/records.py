"""Dataclasses whose methods are not compiled at every start-up.

``@dataclass`` writes the source of ``__init__``, ``__repr__``, ``__eq__``,
``__hash__`` and, for a frozen class, ``__setattr__`` and ``__delattr__``, and
compiles it each time the class is defined: 0.96 ms a frozen class of five
fields on Python 3.11 here, 0.83 ms on 3.13, on every run, since generated code
is never in a ``.pyc``. The fifty dataclasses a ``check`` imports cost 15% of a bare
``Usd.Stage.Open`` of a 1k-prim file (valgrind: 136M of 884M instructions).

``@record`` gives a class the same dataclass (``dataclasses.fields``,
``replace``, ``asdict`` and ``is_dataclass`` work on it, and the field options
``default``, ``default_factory``, ``init``, ``repr``, ``compare`` and
``kw_only``) and the same behaviour: equality by class and compared fields,
the hash of a frozen class (of its compared fields), ``FrozenInstanceError`` on
assignment, ``__post_init__``. The methods are these functions, shared by
every record and compiled once into this module's ``.pyc``; each class only
keeps the tuples of its fields. Creating an instance costs about a microsecond
more than a dataclass's. Not supported (use ``@dataclass``): ``order``,
``slots``, ``InitVar``, a field's own ``hash``.

Even without its methods, the dataclass's fields (``dataclasses``' reading of
the class's string annotations) cost about 0.4M instructions a class, and a
``check`` of one file defines sixty records of which it inspects eleven. So a
record's dataclass is made when it is first asked for (its fields,
``replace``, ``asdict``, ``is_dataclass``, a subclass's dataclass), once,
under a lock; the shared methods read a plain record's fields from its own
annotations and defaults (``_plain_rows``, which dataclasses would read
alike), and any other record's from its dataclass.
"""

from __future__ import annotations

import dataclasses
import re
import sys
import threading
import types
import typing
from collections.abc import Callable, Iterable
from dataclasses import MISSING, Field, FrozenInstanceError
from typing import Any, TypeVar, dataclass_transform, overload

_T = TypeVar("_T", bound=type)


class _Layout:
    """What the shared methods need of one record class, computed once."""

    __slots__ = ("positional", "keyword", "fields", "shown", "compared", "all_positional")

    def __init__(self, rows: list[_Row]) -> None:
        self.positional = tuple(r[0] for r in rows if r[3] and not r[6])
        self.keyword = frozenset(r[0] for r in rows if r[3])
        #: (name, default, default_factory) in field order; MISSING where there is none.
        self.fields = tuple(r[:3] for r in rows)
        self.shown = tuple(r[0] for r in rows if r[4])
        self.compared = tuple(r[0] for r in rows if r[5])
        #: Every field is a positional __init__ argument: a call that passes
        #: them all by position needs no defaults (_init's fast path).
        self.all_positional = len(self.positional) == len(rows)


def _layout(record: object) -> _Layout:
    layout: _Layout | None = type(record).__record_layout__  # type: ignore[attr-defined]
    return layout if layout is not None else _made(type(record))


class _Fields:
    """A record's ``__dataclass_fields__`` until its dataclass is made: asked
    (``dataclasses.fields``, ``replace``, ``is_dataclass``, a subclass's dataclass),
    it makes it and answers with the fields that replace it."""

    def __init__(self, owner: type, kw_only: bool) -> None:
        self.owner, self.kw_only = owner, kw_only

    def __get__(self, instance: object, cls: type | None = None) -> dict[str, Field[Any]]:
        with _MAKING:
            if self.owner.__dict__["__dataclass_fields__"] is self:
                dataclasses.dataclass(
                    self.owner, init=False, repr=False, eq=False, kw_only=self.kw_only
                )
        fields: dict[str, Field[Any]] = self.owner.__dict__["__dataclass_fields__"]
        return fields


#: dataclasses' reading of a string annotation's leading name
#: (``_MODULE_IDENTIFIER_RE``, Lib/dataclasses.py).
_LEADING_NAME = re.compile(r"^(?:\s*(\w+)\s*\.)?\s*(\w+)")
_SPECIAL_NAMES = ("ClassVar", "InitVar", "KW_ONLY")


def _maybe_special(annotation: object, namespace: dict[str, Any]) -> bool:
    """Whether dataclasses might read ``annotation`` as a ClassVar, an InitVar
    or KW_ONLY (it looks the leading name up in the class's module); True
    whenever in doubt."""
    if not isinstance(annotation, str):
        return True
    match = _LEADING_NAME.match(annotation)
    if match is None:
        return False
    name = match.group(2)
    found = namespace.get(name)
    return (
        name in _SPECIAL_NAMES
        or found is typing.ClassVar
        or getattr(found, "__origin__", None) is typing.ClassVar
        or found is dataclasses.InitVar
        or type(found) is dataclasses.InitVar
        or found is dataclasses.KW_ONLY
    )


#: One field as the shared methods read it: name, default, default_factory
#: (MISSING where there is none), init, repr, compare, kw_only.
_Row = tuple[str, Any, Any, bool, bool, bool, bool]


def _rows(fields: Iterable[Field[Any]]) -> list[_Row]:
    return [
        (f.name, f.default, f.default_factory, f.init, f.repr, f.compare, bool(f.kw_only))
        for f in fields
    ]


def _plain_rows(cls: type, kw_only: bool) -> list[_Row] | None:
    """The fields dataclasses would give ``cls``, read without it for the plain
    case (no dataclass base; no ClassVar, InitVar or KW_ONLY; no default it
    refuses); None for any other: dataclasses makes those. The class is left
    as it is (a Field stays its attribute until dataclasses makes the fields)."""
    if any("__dataclass_fields__" in base.__dict__ for base in cls.__mro__[1:]):
        return None
    module = sys.modules.get(cls.__module__)
    namespace = module.__dict__ if module is not None else {}
    annotations = cls.__dict__.get("__annotations__", {})
    for name, value in cls.__dict__.items():
        if isinstance(value, Field) and name not in annotations:
            return None  # dataclasses: "is a field but has no type annotation"
    rows: list[_Row] = []
    for name, annotation in annotations.items():
        if _maybe_special(annotation, namespace):
            return None
        value = getattr(cls, name, MISSING)
        if isinstance(value, Field):
            own = value.kw_only
            row = (name, value.default, value.default_factory, value.init, value.repr,
                   value.compare, kw_only if own is MISSING else bool(own))  # fmt: skip
        elif isinstance(value, types.MemberDescriptorType):
            return None  # a slot: dataclasses reads no default
        else:
            row = (name, value, MISSING, True, True, True, kw_only)
        if row[1].__class__.__hash__ is None:
            return None  # a mutable default: dataclasses refuses it
        rows.append(row)
    return rows


#: Held while a dataclass is made: two threads must not make one twice (the
#: second would read a factory's field as having no default). Reentrant: a
#: subclass's dataclass makes its parent's.
_MAKING = threading.RLock()


def _made(cls: type) -> _Layout:
    """The layout of ``cls``'s nearest record class, its dataclass made first
    if it was not yet."""
    owner = next(c for c in cls.__mro__ if "__record_layout__" in c.__dict__)
    with _MAKING:
        layout: _Layout | None = owner.__dict__["__record_layout__"]
        if layout is None:
            pending = owner.__dict__["__dataclass_fields__"]
            plain = _plain_rows(owner, pending.kw_only) if isinstance(pending, _Fields) else None
            # The plain case needs no dataclass yet (its fields are read alike: a
            # test compares every record's); any other makes it now.
            rows = plain if plain is not None else _rows(dataclasses.fields(owner))
            layout = owner.__record_layout__ = _Layout(rows)  # type: ignore[attr-defined]
    return layout


def _init(self: object, *args: Any, **kwargs: Any) -> None:
    layout = _layout(self)
    if not kwargs and layout.all_positional and len(args) == len(layout.positional):
        # The common call (a Target, a Finding built by position): every field given.
        self.__dict__.update(zip(layout.positional, args, strict=True))
    else:
        _fill(self, layout, _arguments(type(self).__qualname__, layout, args, kwargs))
    post_init = getattr(self, "__post_init__", None)
    if post_init is not None:
        post_init()


def _arguments(
    name: str, layout: _Layout, args: tuple[Any, ...], kwargs: dict[str, Any]
) -> dict[str, Any]:
    """The fields an __init__ call gives, by name; TypeError as dataclass's
    __init__ raises it for too many, unknown or repeated arguments."""
    if len(args) > len(layout.positional):
        raise TypeError(
            f"{name}.__init__() takes {len(layout.positional) + 1} positional arguments "
            f"but {len(args) + 1} were given"
        )
    values = dict(zip(layout.positional, args, strict=False))
    for key, value in kwargs.items():
        if key not in layout.keyword:
            raise TypeError(f"{name}.__init__() got an unexpected keyword argument {key!r}")
        if key in values:
            raise TypeError(f"{name}.__init__() got multiple values for argument {key!r}")
        values[key] = value
    return values


def _fill(record: object, layout: _Layout, values: dict[str, Any]) -> None:
    """Set every field: the value given, else its default; TypeError for a
    required one not given."""
    state = record.__dict__  # as object.__setattr__, which a frozen dataclass's __init__ uses
    for key, default, factory in layout.fields:
        if key in values:
            state[key] = values[key]
        elif default is not MISSING:
            state[key] = default
        elif factory is not MISSING:
            state[key] = factory()
        elif key in layout.keyword:
            raise TypeError(
                f"{type(record).__qualname__}.__init__() missing required argument: {key!r}"
            )


def _repr(self: object) -> str:
    shown = ", ".join(f"{key}={getattr(self, key)!r}" for key in _layout(self).shown)
    return f"{type(self).__qualname__}({shown})"


def _key(self: object) -> tuple[Any, ...]:
    return tuple([getattr(self, key) for key in _layout(self).compared])


def _eq(self: object, other: object) -> bool:
    if other.__class__ is not self.__class__:
        return NotImplemented
    return _key(self) == _key(other)


def _hash(self: object) -> int:
    return hash(_key(self))


def _frozen_setattr(self: object, name: str, value: Any) -> None:
    raise FrozenInstanceError(f"cannot assign to field {name!r}")


def _frozen_delattr(self: object, name: str) -> None:
    raise FrozenInstanceError(f"cannot delete field {name!r}")


def _make(cls: _T, frozen: bool, kw_only: bool) -> _T:
    if cls.__doc__ is None:
        # dataclass would write one from inspect.signature(cls), and of a class
        # whose __init__ is still object's, inspect parses the text signature:
        # compiling tokenize's patterns costs 14 ms, once per process.
        fields = cls.__dict__.get("__annotations__", {})
        cls.__doc__ = f"{cls.__name__}({', '.join(fields)})"
    if any(isinstance(v, Field) and v.hash is not None for v in cls.__dict__.values()):
        raise TypeError(f"{cls.__qualname__}: a field's own hash needs @dataclass, not @record")
    # The dataclass without generated methods (its fields, nothing compiled),
    # made at first need (_made).
    cls.__dataclass_fields__ = _Fields(cls, kw_only)  # type: ignore[attr-defined]
    cls.__record_layout__ = None  # type: ignore[attr-defined]
    cls.__init__ = _init  # type: ignore[misc]
    cls.__repr__ = _repr  # type: ignore[assignment, method-assign]
    cls.__eq__ = _eq  # type: ignore[assignment, method-assign]
    if frozen:
        cls.__hash__ = _hash  # type: ignore[assignment, method-assign]
        cls.__setattr__ = _frozen_setattr  # type: ignore[assignment, method-assign]
        cls.__delattr__ = _frozen_delattr  # type: ignore[assignment, method-assign]
    else:
        cls.__hash__ = None  # type: ignore[assignment]  # as a dataclass with eq: unhashable
    return cls


@overload
def record(cls: _T, /) -> _T: ...


@overload
def record(*, frozen: bool = False, kw_only: bool = False) -> Callable[[_T], _T]: ...


@dataclass_transform(field_specifiers=(dataclasses.field, Field))
def record(
    cls: _T | None = None, /, *, frozen: bool = False, kw_only: bool = False
) -> _T | Callable[[_T], _T]:
    """``@dataclass`` (with ``frozen`` and ``kw_only``) without its start-up cost."""

    def wrap(cls: _T) -> _T:
        return _make(cls, frozen, kw_only)

    return wrap if cls is None else wrap(cls)


__all__ = ["record"]
