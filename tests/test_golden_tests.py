"""Golden tests of templates (engine test, issue 15): the seeded tests pass on the seeded
templates, a draft that breaks an expectation fails the test that states it (the released
version still passes), each kind of expectation holds and fails as documented, and coverage
lists the rows nothing exercises."""
from __future__ import annotations

import json
import math

import psycopg
import pytest

from engine.programs.instantiate import instantiate_gear
from engine.programs.options import RunMode
from engine.release.coverage import coverage
from engine.release.golden import run_golden_tests
from engine.templates.expectations import Context, first_difference

SEEDED_CLASSES = {"spur", "helical", "duplex", "taper", "crowned", "worm_wheel", "turning_iso", "turning_840d"}

# A helical program as an 840D hobber reads it, written here: m3 z41 beta 15 right hand, hob z0 1.
PROGRAM = ["%_N_T_MPF", "; X99 IS A COMMENT", "G90 G71 G94", "G25 X50.500 Y-1.000 Z-24.380", "G0 A=-12.628",
           "EGDEF(C,B,1,Z,1)", 'EGON(C,"FINE",B,-1,41,Z,-0.241126,1)', "M8", "G0 X61.000 Z19.576",
           "G1 X51.500 F13.3", "G1 Z-23.380 F38.8", "G1 X48.000 Z-50.000", "G0 X61.000", "M30"]
NAMES = {"mn": 3.0, "z2": 41, "z0": 1, "beta": 15.0, "da0": 70.0, "df2": 33.0, "h_hob": 1, "h_gear": 1}
# dX/dZ of the last G1 block moving X and Z: from X51.5 Z-23.38 to X48 Z-50
SLOPE = (48.0 - 51.5) / (-50.0 + 23.38)

HOLDS = ["line: M30", "line:   M8  ", "no line: M9", "line 3: G90 G71 G94", "last line: M30",
         r'match: ^EGON\(C,"FINE",B,-1,41', "no match: ^G26", "EGON ratio = -h_hob*z0/z2",
         "EGON Z factor = -h_gear*360*sin(radians(beta))/(pi*mn*z2)", "first A = -12.628",
         "first A = h_hob*2.3715 - h_gear*beta ± 0.001", "first G1 X = (df2 + da0)/2", "max X = 61",
         "last X = 61 +- 0", "min G1 Z = -50", f"XZ slope = {SLOPE!r} ± 0.0001", "count of G1 = 3",
         "count of G01 = 3", "count of M30 = 1", "line count = 14"]
FAILS = {   # expectation → what the failure must say
    "line: M7": "no such line",
    "no line: M8": "line 8: M8",
    "line 3: G91": "line 3: G90 G71 G94",
    "last line: M8": "line 14: M30",
    "match: ^G26": "no line matches",
    "no match: ^G25": "line 4 matches",
    "EGON ratio = h_hob*z0/z2": "program has -0.0243902 (line 7:",
    "first A = -12.62": "program has -12.628 (line 5: G0 A=-12.628)",
    "last X = (df2 + da0)/2 ± 0.01": "expected last X = (df2 + da0)/2 = 51.500 ± 0.01, program has 61.000 (line 13",
    "count of G1 = 2": "program has 3",
    "EGON Y factor = 1": "program has no EGON Y factor",
    "first Y = 0": "program has no first Y",
    "mean X = 1": "unknown property 'mean X'",
    "last X = no_such_name": "unknown parameter 'no_such_name'",
    "last X = __import__('os')": "expression",
    "last X = 1 ± wide": "tolerance 'wide' is not a number",
    "match: (": "not a regular expression",
    "the program looks right": "cannot read expectation",
}


@pytest.mark.parametrize("expectation", HOLDS)
def test_each_kind_of_expectation_holds_on_a_program_that_meets_it(expectation):
    assert first_difference([expectation], Context(PROGRAM, NAMES)) is None


@pytest.mark.parametrize("expectation", FAILS)
def test_each_kind_of_expectation_fails_naming_the_difference(expectation):
    problem = first_difference(["line: M30", expectation], Context(PROGRAM, NAMES))
    assert problem is not None and FAILS[expectation] in problem, problem


def test_the_default_tolerance_is_what_the_program_printed():
    """X51.500 is printed to 3 decimals: 51.5004 is the same number, 51.5006 is not."""
    assert first_difference(["first G1 X = 51.5004"], Context(PROGRAM, NAMES)) is None
    assert first_difference(["first G1 X = 51.5006"], Context(PROGRAM, NAMES)) is not None


def test_every_seeded_test_passes_on_the_seeded_templates(conn):
    results = run_golden_tests(conn)
    assert [result.failure for result in results if not result.passed] == []
    assert SEEDED_CLASSES <= {result.gear_class for result in results}
    assert all(result.row_ids and set(result.row_ids) <= set(result.ran_rows) for result in results)


def test_seeded_expectations_are_the_reference_formulas(conn):
    """The seeded gear 43 (m3 z41 beta 15 right, hob z0 1 right): its test states k_B = -z0/z2
    and the differential -360 sin(beta)/(pi mn z2) (hobbing.md §A7)."""
    expect = conn.execute("SELECT expect FROM template_test "
                          "WHERE gear_class = 'helical' AND gear_id = 43").fetchone()[0]
    lines = ['EGON(C,"FINE",B,-1,41,Z,-0.241126,1)']
    assert first_difference([e for e in expect if e.startswith("EGON")], Context(lines, NAMES)) is None
    assert round(-360 * math.sin(math.radians(15)) / (math.pi * 3 * 41), 6) == -0.241126


def test_a_draft_that_breaks_an_expectation_fails_that_test_and_released_still_passes(conn):
    conn.execute("UPDATE template_view SET p_emit = 'not coolant' WHERE gear_class = 'spur' AND id = 1800")
    results = {result.name: result for result in run_golden_tests(conn, ["spur"])}
    broken = results["gear42-default"]
    assert not broken.passed and broken.draft
    assert broken.failure.startswith("test spur/gear42-default: expected 'line: M8'"), broken.failure
    released = run_golden_tests(conn, ["spur"], draft=False)
    assert all(result.passed and not result.draft for result in released)
    assert broken.version > released[0].version


def test_a_broken_expression_in_a_draft_fails_naming_row_and_column(conn):
    conn.execute("""UPDATE template_view SET o = 'f"G1 X{cut_xx:.3f}"' WHERE gear_class = 'spur' AND id = 2600""")
    for result in run_golden_tests(conn, ["spur"]):
        assert not result.passed
        assert f"test spur/{result.name}: class spur row 2600 column o: unknown parameter 'cut_xx'" in result.failure


def test_a_test_of_a_class_without_released_version_fails_when_released_is_asked(conn):
    conn.execute("INSERT INTO gear_class (name, parent) VALUES ('spur_new', 'spur')")
    conn.execute("INSERT INTO template_test (gear_class, name, gear_id, expect) VALUES ('spur_new', 't', 42, "
                 "ARRAY['line: M30'])")
    [result] = run_golden_tests(conn, ["spur_new"], draft=False)
    assert not result.passed and "spur_new" in result.failure


def test_coverage_lists_a_new_draft_row_until_a_program_emits_it(conn):
    conn.execute("INSERT INTO template_view (gear_class, id, t, n, o, p_emit) "
                 "VALUES ('spur', 3190, 'main', 1, '\"; CHECKED BY QA\"', 'gear_id == 46')")
    assert 3190 in {row.row_id for row in coverage(conn, classes=["spur"])}
    program = instantiate_gear(conn, 46, mode=RunMode(draft=True))
    assert 3190 in program.row_ids
    assert 3190 not in {row.row_id for row in coverage(conn, classes=["spur"])}


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_engine_test_cli_json_is_one_line_and_fails_on_a_broken_draft(run):
    result = run("test", "--json")
    assert result.exit_code == 0, result.output
    assert result.output.count("\n") == 1
    summary = json.loads(result.output)
    assert summary["failed"] == 0 and summary["passed"] >= len(SEEDED_CLASSES)
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE template_view SET p_emit = 'not coolant' WHERE gear_class = 'spur' AND id = 1800")
    failing = run("test", "--class", "spur")
    assert failing.exit_code == 1
    assert "FAIL spur/gear42-default v" in failing.output and "(draft): expected 'line: M8'" in failing.output
    assert run("test", "--class", "spur", "--released").exit_code == 0


def test_engine_test_without_tests_for_the_class_says_so(run):
    with psycopg.connect(run.url) as conn:
        conn.execute("INSERT INTO gear_class (name, parent) VALUES ('spur_new', 'spur')")
    result = run("test", "--class", "spur_new")
    assert result.exit_code == 1 and "no golden tests for class spur_new" in result.output


def test_engine_test_coverage_json(read_only_run):
    result = read_only_run("test", "--coverage", "--class", "spur", "--json")
    assert result.exit_code == 0 and result.output.count("\n") == 1
    rows = json.loads(result.output)["uncovered"]
    assert rows and all(row["class"] in ("spur", "duplex") for row in rows)
