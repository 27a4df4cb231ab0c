"""The parametrised tests, sampled for the fast subset (issue 28: under 60 s on two cores): a test
function with MATRIX_SIZE parameter sets or more keeps one set in SAMPLE_EVERY in `pytest -m "not
slow"`; the others are marked `slow`, so the whole suite (`make test`, `.ci/run`) still runs every
one of them.

Which sets are kept is fixed: a set is kept when the CRC-32 of its id (the text between the
brackets of the node id, the same on every run and every machine) falls on SAMPLE_EVERY. A case
id shared by several functions of one module (test_hobbing_reference.py's gear/hob/machine
cases) is therefore kept, or not, in all of them at once, and the module makes its program once.
Every function keeps at least MATRIX_KEEP sets (the first ids in sorted order beyond the hash's),
so no check of the matrix drops out of the fast run."""
from __future__ import annotations

import zlib
from collections import defaultdict

import pytest

MATRIX_SIZE = 2       # parameter sets of one function from which on it is sampled
SAMPLE_EVERY = 8      # one set in 8 is kept in the fast subset
MATRIX_KEEP = 1       # but never fewer than this many per function


def parameter_id(item) -> str:
    return item.nodeid.partition("[")[2].rpartition("]")[0]


def kept(ids: list[str]) -> set[str]:
    """The parameter ids of one function kept in the fast subset."""
    chosen = {one for one in ids if zlib.crc32(one.encode()) % SAMPLE_EVERY == 0}
    for one in sorted(ids):
        if len(chosen) >= MATRIX_KEEP:
            break
        chosen.add(one)
    return chosen


def mark_matrices(items) -> int:
    """Marks `slow` the sets of every matrix left out of the fast subset; returns how many."""
    functions = defaultdict(list)
    for item in items:
        if "[" in item.nodeid:
            functions[item.nodeid.partition("[")[0]].append(item)
    marked = 0
    for members in functions.values():
        if len(members) < MATRIX_SIZE:
            continue
        keep = kept([parameter_id(item) for item in members])
        for item in members:
            if parameter_id(item) not in keep:
                item.add_marker(pytest.mark.slow)
                marked += 1
    return marked
