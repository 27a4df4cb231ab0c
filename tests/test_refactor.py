"""The nightly refactor (design notes §5): identical bodies merged, every class's assembled
template byte-identical, no body stored twice, a second run changes nothing, and the
near-duplicate lines reported with Sim = K / (M + N − K) computed by a plain LCS table (test_similarity)."""
from __future__ import annotations

import json

import psycopg
import pytest
from helpers.refactor import bodies_stored_twice, component_count, duplicate_row_body, exports, lcs_sim
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from engine.errors import EngineError
from engine.library.refactor import check_invariants, refactor, template_digests
from engine.library.similarity import nc_units
from engine.templates.rows import TemplateRow
from engine.templates.store import ensure_class, replace_template


def test_seeded_library_is_stored_once_and_a_run_changes_nothing(conn):
    before = exports(conn)
    report = refactor(conn)
    assert report.changed is False
    assert report.components_before == report.components_after == component_count(conn)
    assert exports(conn) == before


def test_duplicate_bodies_are_merged_and_every_export_stays_byte_identical(conn):
    original, copy = duplicate_row_body(conn, "spur", 1400)
    second_original, second_copy = duplicate_row_body(conn, "worm_wheel", 1410)
    count = component_count(conn)
    assert bodies_stored_twice(conn) == 2
    before = exports(conn)

    report = refactor(conn)

    assert report.changed is True
    assert (report.components_before, report.components_after) == (count, count - 2)
    assert component_count(conn) == count - 2
    assert bodies_stored_twice(conn) == 0
    assert exports(conn) == before
    pointed = conn.execute("SELECT component_id FROM assembly WHERE (gear_class, id) IN "
                           "(('spur', 1400), ('worm_wheel', 1410)) ORDER BY gear_class").fetchall()
    assert pointed == [(original,), (second_original,)]   # the lowest id of each body is kept
    assert conn.execute("SELECT count(*) FROM component WHERE id IN (%s, %s)",
                        (copy, second_copy)).fetchone()[0] == 0


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_second_run_reports_nothing_changed(conn):
    duplicate_row_body(conn, "helical", 1400)
    assert refactor(conn).changed is True
    after_first = exports(conn)
    again = refactor(conn)
    assert again.changed is False
    assert again.components_before == again.components_after
    assert exports(conn) == after_first


def test_unused_components_are_deleted(conn):
    count = component_count(conn)
    conn.execute("INSERT INTO component (t, o) VALUES ('main', '\"; NOBODY USES THIS\"')")
    report = refactor(conn)
    assert report.changed is True
    assert report.components_after == count


def test_near_duplicates_between_spur_and_helical_coupling_lines(conn):
    report = refactor(conn, threshold=0.6)
    spur, helical = ["EGDEF", "(", "C", ",", "B", ",", "1", ")"], \
        ["EGDEF", "(", "C", ",", "B", ",", "1", ",", "Z", ",", "1", ")"]
    expected = lcs_sim(spur, helical)
    assert expected == pytest.approx(8 / 12)
    found = [pair for pair in report.near_duplicates
             if {pair["a"], pair["b"]} == {'"EGDEF(C,B,1)"', '"EGDEF(C,B,1,Z,1)"'}]
    assert len(found) == 1
    pair = found[0]
    assert pair["t"] == "sync"
    assert pair["sim"] == pytest.approx(expected, abs=1e-4)
    uses = {pair["a"]: pair["rows_a"], pair["b"]: pair["rows_b"]}
    assert ["spur", 1400] in uses['"EGDEF(C,B,1)"']
    assert ["helical", 1400] in uses['"EGDEF(C,B,1,Z,1)"']
    assert all(0.6 - 1e-4 <= p["sim"] < 1 and p["a"] != p["b"] for p in report.near_duplicates)


def test_threshold_keeps_only_closer_pairs(conn):
    # Y against Z axis in the coupling: 11 of 12 tokens in common, Sim = 11/13 ≥ 0.8.
    axis_y = ["EGDEF", "(", "C", ",", "B", ",", "1", ",", "Y", ",", "1", ")"]
    axis_z = ["EGDEF", "(", "C", ",", "B", ",", "1", ",", "Z", ",", "1", ")"]
    report = refactor(conn, threshold=0.8)
    by_texts = {frozenset((p["a"], p["b"])): p for p in report.near_duplicates}
    close = by_texts[frozenset(('"EGDEF(C,B,1,Y,1)"', '"EGDEF(C,B,1,Z,1)"'))]
    assert close["sim"] == pytest.approx(lcs_sim(axis_y, axis_z), abs=1e-4)
    assert frozenset(('"EGDEF(C,B,1)"', '"EGDEF(C,B,1,Z,1)"')) not in by_texts   # Sim 2/3 < 0.8
    assert all(p["sim"] >= 0.8 - 1e-4 for p in report.near_duplicates)


def test_invariant_check_names_the_class_whose_template_would_change(conn):
    snapshot = template_digests(conn)
    _, copy = duplicate_row_body(conn, "worm_wheel", 1410)   # a leaf class: no class inherits it
    conn.execute("UPDATE component SET o = '\"EGDEF(C,B,2)\"' WHERE id = %s", (copy,))
    with pytest.raises(EngineError, match="class 'worm_wheel'"):
        check_invariants(conn, snapshot)


def test_invariant_check_refuses_a_body_stored_twice(conn):
    duplicate_row_body(conn, "taper", 1410)
    with pytest.raises(EngineError, match="stored 2 times"):
        check_invariants(conn, template_digests(conn))


# Bodies (t, o, condition) valid in any class; ids keep the module order (main < prep < sync < …).
POOL = [("main", '"G90 G71 G94"', None), ("main", '"WALIMON"', None), ("prep", '"M20"', None),
        ("prep", '"G0 A=0"', "beta == 0"), ("sync", '"EGDEF(C,B,1)"', None),
        ("sync", '"EGDEF(C,B,1,Z,1)"', None), ("cutcond", '"M8"', None), ("cutcond", '"M8"', "cuts > 1")]
MODULE_BASE = {"main": 100, "prep": 1200, "sync": 1400, "cutcond": 1700}

library = st.lists(st.lists(st.tuples(st.sampled_from(range(len(POOL))), st.booleans()),
                            min_size=1, max_size=6), min_size=2, max_size=4)


@pytest.mark.slow
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(classes=library, derive=st.booleans())
def test_random_libraries_refactor_losslessly_once_and_idempotently(conn, classes, derive):
    with conn.transaction(force_rollback=True):
        for number, picks in enumerate(classes):
            name = f"prop_{number}"
            ensure_class(conn, name, "prop_0" if derive and number else None)
            rows = [TemplateRow(MODULE_BASE[POOL[p][0]] + 10 * i, POOL[p][0], 1, None, None,
                                POOL[p][1], POOL[p][2]) for i, (p, _) in enumerate(picks)]
            replace_template(conn, name, rows)
            for row, (_, copy_it) in zip(rows, picks):
                own = conn.execute("SELECT 1 FROM assembly WHERE gear_class = %s AND id = %s",
                                   (name, row.id)).fetchone()
                if copy_it and own:
                    duplicate_row_body(conn, name, row.id)
        before = exports(conn)
        first = refactor(conn)
        assert exports(conn) == before
        assert bodies_stored_twice(conn) == 0
        assert first.components_after == component_count(conn)
        second = refactor(conn)
        assert second.changed is False
        assert second.components_before == second.components_after == first.components_after
        assert exports(conn) == before


# Any library: bodies drawn from NC words (f-strings when they hold a field), with or
# without conditions and computations, classes deriving from any earlier class, some rows
# pointing at copies of their bodies as SQL edits leave them.
NC_WORDS = ["G0", "G1", "X", "Z", "F", "M8", "{x:.3f}", "{feed}", "; CUT"]
CONDITIONS = [None, "cuts > 1", "coolant", "shift_y <> 0"]
COMPUTATIONS = [None, "k = 1", "x2 = x * 2"]


@st.composite
def random_body(draw):
    words = " ".join(draw(st.lists(st.sampled_from(NC_WORDS), min_size=1, max_size=6)))
    o = f'f"{words}"' if "{" in words else f'"{words}"'
    s = draw(st.sampled_from(COMPUTATIONS))
    return (draw(st.sampled_from(list(MODULE_BASE))), o, "cuts > 1" if s and draw(st.booleans()) else None,
            s, draw(st.sampled_from(CONDITIONS)))


random_library = st.lists(st.tuples(st.lists(st.tuples(random_body(), st.booleans()), min_size=1, max_size=8),
                                    st.integers(min_value=-1, max_value=6)), min_size=1, max_size=5)


def store_random_library(conn, classes) -> None:
    for number, (bodies, parent) in enumerate(classes):
        name = f"any_{number}"
        ensure_class(conn, name, f"any_{parent}" if 0 <= parent < number else None)
        rows = {MODULE_BASE[t] + 10 * i: TemplateRow(MODULE_BASE[t] + 10 * i, t, 1, p_calc, s, o, p_emit)
                for i, ((t, o, p_calc, s, p_emit), _) in enumerate(bodies)}
        replace_template(conn, name, sorted(rows.values(), key=lambda row: row.id))
        for i, ((t, *_), copy_it) in enumerate(bodies):
            own = conn.execute("SELECT 1 FROM assembly WHERE gear_class = %s AND id = %s",
                               (name, MODULE_BASE[t] + 10 * i)).fetchone()
            if copy_it and own:
                duplicate_row_body(conn, name, MODULE_BASE[t] + 10 * i)


def expected_near_duplicates(conn, threshold: float) -> set[frozenset]:
    """Every pair of stored line texts of one module type whose NC units have threshold ≤ Sim < 1."""
    texts = conn.execute("SELECT DISTINCT c.t, c.o FROM assembly a JOIN component c ON c.id = a.component_id "
                         "WHERE c.o IS NOT NULL").fetchall()
    units = {text: nc_units(text) for _, text in texts}   # once per text, not once per pair (issue 28: 50 s of 62)
    found = set()
    for index, (t, a) in enumerate(texts):
        for u, b in texts[index + 1:]:
            if t == u and threshold - 1e-9 <= lcs_sim(units[a], units[b]) < 1 - 1e-9:
                found.add(frozenset((t, a, b)))
    return found


@pytest.mark.slow
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(classes=random_library, threshold=st.sampled_from([0.5, 0.8]))
def test_any_library_refactors_losslessly_stored_once_idempotently_with_every_near_duplicate(
        conn, classes, threshold):
    with conn.transaction(force_rollback=True):
        store_random_library(conn, classes)
        before = exports(conn)
        first = refactor(conn, threshold)
        assert exports(conn) == before
        assert bodies_stored_twice(conn) == 0
        assert first.components_after == component_count(conn)
        reported = {frozenset((pair["t"], pair["a"], pair["b"])) for pair in first.near_duplicates}
        assert reported == expected_near_duplicates(conn, threshold)
        second = refactor(conn, threshold)
        assert second.changed is False
        assert second.components_before == second.components_after == first.components_after
        assert exports(conn) == before


def test_cli_json_reports_a_merge_then_nothing(run):
    first = run("refactor", "--json")
    assert first.exit_code == 0, first.output
    keys = json.loads(first.stdout)
    assert {"changed", "components_before", "components_after", "near_duplicates"} <= set(keys)
    assert keys["changed"] is False
    with psycopg.connect(run.url) as conn:
        duplicate_row_body(conn, "spur", 1400)
    merged = json.loads(run("refactor", "--json").stdout)
    assert merged["changed"] is True
    assert merged["components_after"] == merged["components_before"] - 1 == keys["components_after"]
    again = run("refactor")
    assert again.exit_code == 0
    assert "nothing to merge" in again.stdout


def test_cli_threshold_out_of_range_is_refused(read_only_run):
    result = read_only_run("refactor", "--threshold", "1.5")
    assert result.exit_code != 0
    assert "--threshold" in result.output


def test_cli_template_shared_names_the_other_classes(run):
    with psycopg.connect(run.url) as conn:
        for name, second in (("shared_a", '"M8"'), ("shared_b", '"M9"')):
            ensure_class(conn, name)
            replace_template(conn, name, [TemplateRow(100, "main", 1, None, None, '"G90 G71 G94 ; SHARED"', None),
                                          TemplateRow(1700, "cutcond", 1, None, None, second, None)])
    result = run("template", "shared", "--class", "shared_a")
    assert result.exit_code == 0, result.output
    first, second = result.stdout.splitlines()
    assert "shared with 1 class(es): shared_b" in first
    assert "used by this class only" in second
    missing = run("template", "shared", "--class", "no_such_class")
    assert missing.exit_code == 1
    assert "no_such_class" in missing.stderr


@pytest.mark.parametrize("args, words", [(("refactor",), ("--threshold", "--json", "Merge")),
                                         (("template", "shared"), ("--class", "shared"))])
def test_help_texts(read_only_run, args, words):
    result = read_only_run(*args, "--help")
    assert result.exit_code == 0
    assert all(word in result.stdout for word in words)


def test_a_text_used_by_many_classes_lists_ten_uses_and_counts_them_all(conn):
    for number in range(12):
        ensure_class(conn, f"many_{number}")
        replace_template(conn, f"many_{number}",
                         [TemplateRow(100, "main", 1, None, None, '"G90 G71 G94 ; MANY"', None)])
    ensure_class(conn, "few")
    replace_template(conn, "few", [TemplateRow(100, "main", 1, None, None, '"G90 G71 G94 ; FEW"', None)])
    report = refactor(conn, threshold=0.6)
    pair = next(p for p in report.near_duplicates
                if {p["a"], p["b"]} == {'"G90 G71 G94 ; MANY"', '"G90 G71 G94 ; FEW"'})
    uses = {pair["a"]: (pair["uses_a"], pair["rows_a"]), pair["b"]: (pair["uses_b"], pair["rows_b"])}
    many_count, many_rows = uses['"G90 G71 G94 ; MANY"']
    assert many_count == 12
    assert len(many_rows) == 10 and all(name.startswith("many_") and row == 100 for name, row in many_rows)
    assert uses['"G90 G71 G94 ; FEW"'] == (1, [["few", 100]])
    assert pair["sim"] == pytest.approx(lcs_sim(["G90", "G71", "G94", "; MANY"], ["G90", "G71", "G94", "; FEW"]))
