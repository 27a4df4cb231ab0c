"""Literal similarity (design notes §5): the pair search that skips most comparisons finds
exactly the pairs that comparing every pair finds, with Sim = K / (M + N − K) computed
here by a plain longest-common-subsequence table."""
from __future__ import annotations

import pytest
from helpers.refactor import lcs_sim
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.library.similarity import nc_units, similar_pairs


def every_pair(lines, threshold):
    """The quadratic reference: every pair compared."""
    return {(i, j) for i in range(len(lines)) for j in range(i + 1, len(lines))
            if threshold - 1e-9 <= lcs_sim(lines[i], lines[j]) < 1 - 1e-9}


# Few distinct units, so random lines share many of them and land on both sides of t.
unit_lists = st.lists(st.lists(st.sampled_from(["G1", "X", "Z", "F", "{x}", "{z:.3f}", ",", "("]),
                               min_size=0, max_size=9).map(tuple), min_size=0, max_size=25, unique=True)


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@settings(max_examples=300, deadline=None)
@given(lines=unit_lists, threshold=st.sampled_from([0.5, 0.6, 2 / 3, 0.75, 0.8, 0.9, 1.0]))
def test_the_pair_search_finds_what_comparing_every_pair_finds(lines, threshold):
    found = {(i, j): sim for i, j, sim in similar_pairs(lines, threshold)}
    assert set(found) == every_pair(lines, threshold)
    for (i, j), sim in found.items():
        assert sim == pytest.approx(lcs_sim(lines[i], lines[j]))


def test_the_pair_search_agrees_with_rapidfuzz_cdist_on_a_generated_library():
    import numpy
    from rapidfuzz import process
    from rapidfuzz.distance import Indel

    words = ["G0", "G1", "X", "Y", "Z", "F", "M8", "EGON", "(", ")", ","]
    lines = list({tuple(words[(seed * k + k * k) % len(words)] for k in range(1, 3 + seed % 9))
                  + (f"{{p{seed % 40}}}",) for seed in range(400)})
    scores = process.cdist(lines, lines, scorer=Indel.normalized_similarity, workers=-1, dtype=numpy.float64)
    expected = {(i, j) for i in range(len(lines)) for j in range(i + 1, len(lines))
                if 0.8 - 1e-9 <= scores[i][j] / (2 - scores[i][j]) < 1 - 1e-9}
    assert expected   # the library has near-duplicates to find
    assert {(i, j) for i, j, _ in similar_pairs(lines, 0.8)} == expected


@pytest.mark.parametrize("text, units", [
    ('"EGDEF(C,B,1)"', ("EGDEF", "(", "C", ",", "B", ",", "1", ")")),
    ('f"G1 X{x_in:.3f} F{feed:.1f}"', ("G1", "X", "{x_in:.3f}", "F", "{feed:.1f}")),
    ('"G25 X" + str(x_lower)', ("G25", "X", "{str(x_lower)}")),
    ('"G0" if rapid else "G1"', ('"G0"', "if", "rapid", "else", '"G1"')),
    ('"M20 ; TAILSTOCK CLAMP"', ("M20", "; TAILSTOCK CLAMP")),
])
def test_a_line_expression_is_compared_by_the_units_of_its_nc_line(text, units):
    assert nc_units(text) == units


def test_a_reported_pair_has_sim_k_over_m_plus_n_minus_k():
    a = ("EGDEF", "(", "C", ",", "B", ",", "1", ",", "Y", ",", "1", ")")
    b = ("EGDEF", "(", "C", ",", "B", ",", "1", ",", "Z", ",", "1", ")")
    assert list(similar_pairs([a, b], 0.8)) == [(0, 1, pytest.approx(11 / 13))]
    shorter = a[:8] + (")",)
    assert list(similar_pairs([a, shorter], 0.5)) == [(0, 1, pytest.approx(lcs_sim(a, shorter)))]
