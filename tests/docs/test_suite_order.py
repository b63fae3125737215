"""The suite's long files start first (tests/conftest.py): xdist hands files
out in collection order, so a long file collected last would run alone."""

from __future__ import annotations

import os

import pytest
from conftest import pytest_collection_modifyitems, pytest_xdist_auto_num_workers


class _Item:
    def __init__(self, name: str, seconds: float | None = None) -> None:
        self.name = name
        self._mark = None if seconds is None else pytest.mark.heavy(seconds=seconds).mark

    def get_closest_marker(self, name: str) -> pytest.Mark | None:
        return self._mark if name == "heavy" else None


def test_heavy_files_go_first_the_longest_first_and_the_rest_keep_their_order() -> None:
    items = [
        _Item("api_a"),
        _Item("cli_short", 15),
        _Item("cli_b"),
        _Item("running_long", 70),
        _Item("running_long_2", 70),
        _Item("server_c"),
    ]
    pytest_collection_modifyitems(items)  # type: ignore[arg-type]
    assert [i.name for i in items] == [
        "running_long",
        "running_long_2",
        "cli_short",
        "api_a",
        "cli_b",
        "server_c",
    ]


def test_auto_starts_one_worker_more_than_the_cores() -> None:
    # Many tests wait, and a third worker on 2 cores keeps them busier.
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    assert pytest_xdist_auto_num_workers(None) == (cores or 1) + 1  # type: ignore[arg-type]
