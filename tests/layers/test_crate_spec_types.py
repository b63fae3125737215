"""layers/crate.py's check of a crate's spec types, read from the file's bytes
(Sdf's integer coding under LZ4) instead of walking every spec through Sdf: a
spec of no valid type crashes a rule's read, and every path runs this check."""

from __future__ import annotations

import struct
from collections import Counter
from pathlib import Path

import pytest
from cli_support import settings_crate
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pxr import Gf, Sdf, Usd, UsdGeom, Vt

from usdrender_lint.layers.crate import (
    SPEC_TYPES,
    _coded_extremes,
    crate_spec_problem,
    fast_decompress,
)


def encode(values: list[int], common: int | None = None) -> bytes:
    """Sdf's integer coding (pxr/usd/sdf/integerCoding.cpp, 32-bit), written
    the plain way: the deltas' common value, 2-bit kinds, the other deltas."""
    deltas = [value - before for value, before in zip(values, [0, *values], strict=False)]
    if common is None:
        common = Counter(deltas).most_common(1)[0][0] if deltas else 0
    codes = bytearray((len(values) * 2 + 7) // 8)
    others = bytearray()
    for index, delta in enumerate(deltas):
        if delta == common:
            kind = 0
        else:
            kind, code = next((k, c) for k, c, b in _SIZES if -b <= delta < b)
            others += struct.pack("<" + code, delta)
        codes[index // 4] |= kind << (2 * (index % 4))
    return struct.pack("<i", common) + bytes(codes) + bytes(others)


_SIZES = ((1, "b", 1 << 7), (2, "h", 1 << 15), (3, "i", 1 << 31))


def decode(raw: bytes, count: int) -> list[int]:
    """Every integer, one by one (what USD's _DecodeIntegers does)."""
    (common,) = struct.unpack_from("<i", raw)
    pos = 4 + (count * 2 + 7) // 8
    values, value = [], 0
    for index in range(count):
        kind = (raw[4 + index // 4] >> (2 * (index % 4))) & 3
        if kind == 0:
            value += common
        else:
            code = "_bhi"[kind]
            value += struct.unpack_from("<" + code, raw, pos)[0]
            pos += struct.calcsize(code)
        values.append(value)
    return values


def literals(data: bytes) -> bytes:
    """TfFastCompression data holding ``data`` as one LZ4 block of literals."""
    if len(data) < 15:
        return bytes([0, len(data) << 4]) + data
    rest = len(data) - 15
    return bytes([0, 0xF0]) + b"\xff" * (rest // 255) + bytes([rest % 255]) + data


# No deadline: a correctness property, not a timing (a loaded CI machine took
# longer than hypothesis's default 200 ms for one example).
@settings(deadline=None)
@given(
    st.lists(st.integers(0, 1 << 20), min_size=1, max_size=70),
    st.one_of(st.none(), st.integers(-300, 300)),
)
def test_the_extremes_are_those_of_every_integer(values: list[int], common: int | None) -> None:
    """Runs of the common delta are bounded by their ends: the same extremes
    as decoding every integer, whatever the common delta (a rarer one too)."""
    raw = encode(values, common)
    assert decode(raw, len(values)) == values
    extremes = _coded_extremes(raw, len(values), (len(values) * 2 + 7) // 8)
    assert extremes == (min(values), max(values))


def test_runs_of_the_common_delta_reach_past_the_uncommon_values() -> None:
    # 10 steps of +3 after the single uncommon delta: the greatest value ends the run.
    values = [5, *range(8, 38, 3), 2]
    raw = encode(values, common=3)
    assert _coded_extremes(raw, len(values), (len(values) * 2 + 7) // 8) == (2, 35)


def _sections(data: bytes) -> dict[str, tuple[int, int]]:
    (toc,) = struct.unpack_from("<q", data, 16)
    (count,) = struct.unpack_from("<Q", data, toc)
    entries = struct.iter_unpack("<16sqq", data[toc + 8 : toc + 8 + 32 * count])
    return {name.rstrip(b"\0").decode(): (start, size) for name, start, size in entries}


def _tables(specs: bytes) -> tuple[int, list[bytes]]:
    """A SPECS section's spec count and its three compressed tables."""
    (count,) = struct.unpack_from("<Q", specs)
    tables, pos = [], 8
    for _ in range(3):
        (size,) = struct.unpack_from("<Q", specs, pos)
        tables.append(specs[pos + 8 : pos + 8 + size])
        pos += 8 + size
    return count, tables


def spec_types(data: bytes) -> list[int]:
    start, size = _sections(data)["SPECS"]
    count, tables = _tables(data[start : start + size])
    raw = fast_decompress(tables[2], 4 + (count * 2 + 7) // 8 + 4 * count)
    assert raw is not None
    return decode(raw, count)


def with_types_table(data: bytes, table: bytes) -> bytes:
    """The crate with its spec types' table replaced: the new SPECS section
    is appended after the table of contents, whose entry points at it."""
    sections = _sections(data)
    start, size = sections["SPECS"]
    count, tables = _tables(data[start : start + size])
    specs = struct.pack("<Q", count) + b"".join(
        struct.pack("<Q", len(t)) + t for t in (*tables[:2], table)
    )
    index = list(sections).index("SPECS")
    (toc,) = struct.unpack_from("<q", data, 16)
    entry = toc + 8 + 32 * index + 16
    patched = bytearray(data)
    patched[entry : entry + 16] = struct.pack("<qq", len(data), len(specs))
    return bytes(patched) + specs


def _crates(folder: Path) -> list[Path]:
    settings_crate(folder / "settings.usdc")
    stage = Usd.Stage.CreateNew(str(folder / "meshes.usdc"))
    for index in range(300):
        mesh = UsdGeom.Mesh.Define(stage, f"/World/m{index}")
        mesh.CreatePointsAttr(Vt.Vec3fArray([Gf.Vec3f(index)] * 3))
        mesh.GetPrim().GetVariantSets().AddVariantSet("look").AddVariant("red")
    stage.GetRootLayer().Save()
    return [folder / "settings.usdc", folder / "meshes.usdc"]


def test_the_crates_usd_writes_have_valid_spec_types(tmp_path: Path) -> None:
    for path in _crates(tmp_path):
        types = spec_types(path.read_bytes())
        assert set(types) <= set(SPEC_TYPES) and len(set(types)) > 2
        assert crate_spec_problem(path) is None
        # The same types, coded again here: still valid (the rewrite is faithful).
        again = tmp_path / f"again_{path.name}"
        again.write_bytes(with_types_table(path.read_bytes(), literals(encode(types))))
        assert Sdf.Layer.FindOrOpen(str(again)) is not None
        assert crate_spec_problem(again) is None


@pytest.mark.parametrize("bad", [0, 12, -1, 1 << 20])
def test_a_spec_type_out_of_range_is_found(tmp_path: Path, bad: int) -> None:
    (path,) = _crates(tmp_path)[:1]
    types = spec_types(path.read_bytes())
    types[len(types) // 2] = bad
    corrupt = tmp_path / "corrupt.usdc"
    corrupt.write_bytes(with_types_table(path.read_bytes(), literals(encode(types))))
    assert crate_spec_problem(corrupt) == "a spec of no valid type"


def test_types_whose_deltas_run_past_their_data_are_found(tmp_path: Path) -> None:
    """USD then reads the rest from memory that is not the table's."""
    (path,) = _crates(tmp_path)[:1]
    coded = encode(spec_types(path.read_bytes()))
    corrupt = tmp_path / "short.usdc"
    corrupt.write_bytes(with_types_table(path.read_bytes(), literals(coded[:-1])))
    assert crate_spec_problem(corrupt) == "a spec of no valid type"


def test_what_is_not_a_readable_crate_has_no_spec_problem(tmp_path: Path) -> None:
    (tmp_path / "text.usda").write_text("#usda 1.0\n")
    assert crate_spec_problem(tmp_path / "text.usda") is None
    assert crate_spec_problem(tmp_path / "missing.usdc") is None
    (path,) = _crates(tmp_path)[:1]
    # A table USD cannot decompress either: USD says so when it opens the file.
    undecodable = tmp_path / "undecodable.usdc"
    undecodable.write_bytes(with_types_table(path.read_bytes(), b"\x00\xf0"))
    assert crate_spec_problem(undecodable) is None


@pytest.mark.parametrize("size", [1 << 20, (1 << 63) - 1, (1 << 64) - 1])
def test_a_table_size_past_the_section_is_no_spec_problem(
    settings_bytes: bytes, tmp_path: Path, size: int
) -> None:
    """The paths table's stated size sends the read past the section (past
    what an index can hold, at the largest): USD fails to open the file and
    says so; the check answers None and does not raise."""
    start, _ = _sections(settings_bytes)["SPECS"]
    corrupt = bytearray(settings_bytes)
    corrupt[start + 8 : start + 16] = struct.pack("<Q", size)
    path = tmp_path / "huge_table.usdc"
    path.write_bytes(bytes(corrupt))
    assert crate_spec_problem(path) is None


@pytest.fixture(scope="module")
def settings_bytes(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    return settings_crate(tmp_path_factory.mktemp("crate") / "settings.usdc")


@settings(
    max_examples=300, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(st.lists(st.tuples(st.integers(0, 1 << 16), st.integers(0, 255)), min_size=1, max_size=4))
def test_any_flipped_bytes_get_an_answer(
    settings_bytes: bytes, tmp_path_factory: pytest.TempPathFactory, flips: list[tuple[int, int]]
) -> None:
    """Whatever a crate's bytes say, the check answers (None or why) and never raises."""
    data = bytearray(settings_bytes)
    for offset, value in flips:
        data[offset % len(data)] = value
    path = tmp_path_factory.mktemp("flipped") / "flipped.usdc"
    path.write_bytes(bytes(data))
    assert crate_spec_problem(path) in (None, "a spec of no valid type")
