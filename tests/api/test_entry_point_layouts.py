"""The fast entry point reader (entrypoints.py) answers exactly as
importlib.metadata on every layout it reads itself, and hands every other
layout to importlib.metadata. Its start-up gain is measured by
benchmarks/entry_points.py."""

from __future__ import annotations

import sys
import zipfile
from importlib import metadata
from pathlib import Path

import pytest

from usdrender_lint import entrypoints

GROUP = "usdrender_lint.formatters"


def _pairs(found) -> list[tuple[str, str]]:
    return sorted((ep.name, ep.value) for ep in found)


def _dist(site: Path, folder: str, entry_points: str) -> None:
    info = site / folder
    info.mkdir(parents=True)
    name = folder.partition("-")[0]
    metadata_file = "PKG-INFO" if folder.endswith(".egg-info") else "METADATA"
    (info / metadata_file).write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 9\n")
    (info / "entry_points.txt").write_text(entry_points)


@pytest.mark.parametrize("suffix", [".dist-info", ".egg-info"])
def test_a_second_registrant_in_either_layout_reads_as_importlib_does(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, suffix: str
) -> None:
    _dist(tmp_path, f"acme_fmt-1{suffix}", f"[{GROUP}]\nacme = json:dumps\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert _pairs(entrypoints.entry_points(GROUP)) == _pairs(metadata.entry_points(group=GROUP))
    assert "acme" in {ep.name for ep in entrypoints.entry_points(GROUP)}


@pytest.mark.parametrize("suffix", [".dist-info", ".egg-info"])
def test_a_distribution_outside_the_group_keeps_the_fast_answer(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, suffix: str
) -> None:
    _dist(tmp_path, f"other-1{suffix}", "[console_scripts]\nother = json:dumps\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    fast = entrypoints._single_registrant(GROUP)
    assert fast is not None
    assert _pairs(fast) == _pairs(metadata.entry_points(group=GROUP))


def test_a_zip_on_the_path_is_left_to_importlib_metadata(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    archive = tmp_path / "plugins.zip"
    with zipfile.ZipFile(archive, "w") as bundle:
        bundle.writestr("zipped-1.dist-info/METADATA", "Metadata-Version: 2.1\nName: zipped\n")
        bundle.writestr("zipped-1.dist-info/entry_points.txt", f"[{GROUP}]\nzipped = json:dumps\n")
    monkeypatch.syspath_prepend(str(archive))
    assert entrypoints._single_registrant(GROUP) is None
    assert "zipped" in {ep.name for ep in entrypoints.entry_points(GROUP)}


def test_a_finder_with_distributions_of_its_own_is_left_to_importlib_metadata(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    class Finder:
        @staticmethod
        def find_spec(*_args, **_kwargs):
            return None

        @staticmethod
        def find_distributions(*_args, **_kwargs):
            return iter(())

    monkeypatch.setattr(sys, "meta_path", [Finder, *sys.meta_path])
    assert entrypoints._single_registrant(GROUP) is None
    assert _pairs(entrypoints.entry_points(GROUP)) == _pairs(metadata.entry_points(group=GROUP))
