"""The fast subset's sample of the big matrices (tests/helpers/matrix_sample.py): what `pytest -m
"not slow"` keeps of a matrix is fixed, shared by the functions of one case id, never empty, and
nothing else is marked."""
from __future__ import annotations

import zlib

import pytest
from helpers.matrix_sample import MATRIX_KEEP, MATRIX_SIZE, SAMPLE_EVERY, mark_matrices


class Item:
    """What mark_matrices reads of a pytest item: its node id and the markers put on it."""

    def __init__(self, nodeid: str):
        self.nodeid, self.markers = nodeid, []

    def add_marker(self, marker) -> None:
        self.markers.append(marker.name)


def items(function: str, ids: list[str]) -> list[Item]:
    return [Item(f"tests/test_x.py::{function}[{one}]") for one in ids]


def kept_ids(members: list[Item]) -> set[str]:
    return {item.nodeid.partition("[")[2][:-1] for item in members if "slow" not in item.markers}


def test_a_matrix_keeps_the_sets_whose_crc_falls_on_the_sample_and_marks_the_rest_slow():
    ids = [f"case{k}@din" for k in range(200)]
    members = items("test_a", ids)
    mark_matrices(members)
    expected = {one for one in ids if zlib.crc32(one.encode()) % SAMPLE_EVERY == 0}   # the rule, computed here
    assert len(expected) >= MATRIX_KEEP
    assert kept_ids(members) == expected
    assert 200 / SAMPLE_EVERY / 2 < len(expected) < 200 / SAMPLE_EVERY * 2


def test_functions_sharing_case_ids_keep_the_same_cases():
    ids = [f"spur-R-L{k}@mirror" for k in range(60)]
    first, second = items("test_a", ids), items("test_b", ids)
    mark_matrices(first + second)
    assert kept_ids(first) == kept_ids(second)


def test_a_matrix_no_case_of_which_falls_on_the_sample_still_keeps_some():
    ids = [one for one in (f"c{k}" for k in range(400)) if zlib.crc32(one.encode()) % SAMPLE_EVERY][:MATRIX_SIZE]
    members = items("test_a", ids)
    mark_matrices(members)
    assert len(kept_ids(members)) == MATRIX_KEEP


@pytest.mark.parametrize("count", [1, MATRIX_SIZE - 1])
def test_a_small_parametrisation_and_a_plain_test_are_never_marked(count):
    members = items("test_a", [f"c{k}" for k in range(count)]) + [Item("tests/test_x.py::test_plain")]
    assert mark_matrices(members) == 0
    assert all(not item.markers for item in members)
