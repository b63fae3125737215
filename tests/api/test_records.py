"""``@record`` behaves as ``@dataclass`` does, for what the package uses of it."""

from __future__ import annotations

import copy
import dataclasses
import pickle
from dataclasses import field

import pytest

from usdrender_lint.records import record


@record(frozen=True)
class Point:
    """A frozen record with a default, a factory and fields left out of repr and eq."""

    x: int
    y: int = 0
    tags: tuple[str, ...] = field(default_factory=tuple)
    note: str = field(default="", compare=False)
    cache: object = field(default=None, repr=False, compare=False)


@dataclasses.dataclass(frozen=True)
class PointDataclass:
    x: int
    y: int = 0
    tags: tuple[str, ...] = field(default_factory=tuple)
    note: str = field(default="", compare=False)
    cache: object = field(default=None, repr=False, compare=False)


@record
class Counter:
    name: str
    seen: list[str] = field(default_factory=list)
    total: int = field(default=0, init=False)

    def __post_init__(self) -> None:
        self.total = len(self.seen)


@record(frozen=True, kw_only=True)
class Options:
    level: int
    label: str = "x"


@record(frozen=True)
class Child(Point):
    z: int = 0


def test_a_record_is_a_dataclass_with_the_same_fields() -> None:
    assert dataclasses.is_dataclass(Point)
    ours = [(f.name, f.default, f.repr, f.compare) for f in dataclasses.fields(Point)]
    theirs = [(f.name, f.default, f.repr, f.compare) for f in dataclasses.fields(PointDataclass)]
    assert ours == theirs


def test_init_takes_positional_and_keyword_arguments_with_defaults() -> None:
    point = Point(1, tags=("a",))
    assert (point.x, point.y, point.tags, point.note, point.cache) == (1, 0, ("a",), "", None)
    assert list(vars(point)) == ["x", "y", "tags", "note", "cache"]  # field order
    assert Point(1).tags is not None and Point(1).tags == ()


@pytest.mark.parametrize(
    ("args", "kwargs", "message"),
    [
        ((), {}, "missing required argument: 'x'"),
        ((1, 2, (), "", None, 6), {}, "takes 6 positional arguments but 7 were given"),
        ((1,), {"x": 2}, "multiple values for argument 'x'"),
        ((1,), {"w": 2}, "unexpected keyword argument 'w'"),
    ],
)
def test_init_refuses_what_a_dataclass_refuses(
    args: tuple[object, ...], kwargs: dict[str, object], message: str
) -> None:
    with pytest.raises(TypeError, match=message):
        Point(*args, **kwargs)
    with pytest.raises(TypeError):
        PointDataclass(*args, **kwargs)  # type: ignore[arg-type]


def test_repr_equality_and_hash_follow_the_field_options() -> None:
    theirs = repr(PointDataclass(1, 2, note="n", cache=3))
    assert repr(Point(1, 2, note="n", cache=3)) == theirs.replace("PointDataclass", "Point")
    assert repr(Point(1)) == "Point(x=1, y=0, tags=(), note='')"
    assert Point(1, note="a", cache=1) == Point(1, note="b", cache=2)  # not compared
    assert Point(1) != Point(2)
    assert Point(1) != PointDataclass(1)  # another class is never equal
    assert Point(1).__eq__((1, 0, ())) is NotImplemented
    assert hash(Point(1, note="a")) == hash(Point(1, note="b"))
    assert len({Point(1), Point(1), Point(2)}) == 2


def test_a_frozen_record_refuses_assignment_and_deletion() -> None:
    point = Point(1)
    with pytest.raises(dataclasses.FrozenInstanceError):
        point.x = 2  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        del point.x  # type: ignore[misc]
    assert point.x == 1


def test_a_mutable_record_runs_post_init_and_is_unhashable() -> None:
    counter = Counter("a", ["x", "y"])
    assert counter.total == 2  # init=False field, set by __post_init__
    counter.total = 5
    assert counter.total == 5
    with pytest.raises(TypeError, match="takes 3 positional"):
        Counter("a", [], 3)  # type: ignore[call-arg]
    with pytest.raises(TypeError, match="unhashable"):
        hash(counter)
    assert Counter("a").seen is not Counter("a").seen  # a new list each time


def test_kw_only_fields_take_no_positional_argument() -> None:
    assert Options(level=1) == Options(level=1, label="x")
    with pytest.raises(TypeError, match="positional"):
        Options(1)  # type: ignore[misc]


def test_a_subclass_has_its_parents_fields_then_its_own() -> None:
    child = Child(1, 2, z=3)
    assert [f.name for f in dataclasses.fields(child)] == ["x", "y", "tags", "note", "cache", "z"]
    assert repr(child) == "Child(x=1, y=2, tags=(), note='', z=3)"
    assert child != Point(1, 2)


def test_what_a_record_does_not_support_is_refused_when_the_class_is_made() -> None:
    with pytest.raises(TypeError, match="needs @dataclass"):

        @record(frozen=True)
        class Hashed:
            key: int = field(default=0, hash=False)


def test_a_record_without_a_docstring_gets_one_naming_its_fields() -> None:
    assert Counter.__doc__ == "Counter(name, seen, total)"
    assert Point.__doc__ is not None and Point.__doc__.startswith("A frozen record")


def test_replace_asdict_copy_and_pickle_work_on_records() -> None:
    point = Point(1, 2, ("a",), "n")
    assert dataclasses.replace(point, y=5) == Point(1, 5, ("a",), "n")
    assert dataclasses.asdict(point) == {"x": 1, "y": 2, "tags": ("a",), "note": "n", "cache": None}
    assert copy.deepcopy(point) == point
    again = pickle.loads(pickle.dumps(point))
    assert again == point and again.note == "n"
    counter = pickle.loads(pickle.dumps(Counter("a", ["x"])))
    assert (counter.name, counter.seen, counter.total) == ("a", ["x"], 1)


def test_a_record_s_dataclass_is_made_at_its_first_use_once() -> None:
    """Defining a record reads none of its fields (dataclasses' processing, about
    0.4M instructions a class at every start-up); the first use makes its
    dataclass, a subclass's its parent's too, and threads make it once."""
    import threading

    @record(frozen=True)
    class Base:
        name: str
        seen: tuple[str, ...] = field(default_factory=tuple)

    @record(frozen=True)
    class Leaf(Base):
        size: int = 1

    assert "__dataclass_params__" not in Base.__dict__
    assert "__dataclass_params__" not in Leaf.__dict__
    assert [f.name for f in dataclasses.fields(Leaf)] == ["name", "seen", "size"]
    assert "__dataclass_params__" in Base.__dict__  # the subclass's made its parent's

    @record
    class Shared:
        items: list[str] = field(default_factory=list)
        label: str = "x"

    made: list[Shared] = []
    start = threading.Barrier(8)

    def make() -> None:
        start.wait()
        made.append(Shared())

    threads = [threading.Thread(target=make) for _ in range(8)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert [(s.items, s.label) for s in made] == [([], "x")] * 8
    assert len({id(s.items) for s in made}) == 8  # a new list each, from the factory


#: Modules not imported here: those made for a host application (its plugin
#: API), and the command's entry, which installs signal handlers as it is imported.
NOT_IMPORTED = (
    "usdrender_lint.usdplugin",
    "usdrender_lint.assetvalidator",
    "usdrender_lint.__main__",
)


def test_every_record_s_fields_are_read_as_dataclasses_reads_them() -> None:
    """A plain record is laid out from its annotations without dataclasses
    (records._plain_rows, 0.3M instructions a class less); each of the package's
    records still unmade reads the same fields as its dataclass then gives."""
    import importlib
    import pkgutil

    import usdrender_lint
    from usdrender_lint import records

    for module in pkgutil.walk_packages(usdrender_lint.__path__, "usdrender_lint."):
        if not module.name.startswith(NOT_IMPORTED):
            importlib.import_module(module.name)
    pending = {
        cls: cls.__dict__["__dataclass_fields__"]
        for cls in _subclasses(object)
        if isinstance(cls.__dict__.get("__dataclass_fields__"), records._Fields)
    }
    compared = 0
    for cls, fields in pending.items():
        plain = records._plain_rows(cls, fields.kw_only)
        if plain is not None:
            assert plain == records._rows(dataclasses.fields(cls)), cls.__qualname__
            compared += 1
    assert compared > 50


def _subclasses(root: type) -> list[type]:
    found: list[type] = []
    todo, seen = [root], {root}
    while todo:
        for sub in type.__subclasses__(todo.pop()):
            if sub not in seen:
                seen.add(sub)
                found.append(sub)
                todo.append(sub)
    return found
