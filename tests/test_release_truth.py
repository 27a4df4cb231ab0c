"""Records say only what is true (issue 26, finding 7): a releaser who records a release by hand
from SQL, for a draft the engine's gate refused, with invented golden-test results and impact,
leaves a record `engine template history` does not show as passed. It says the release was made
by hand, re-runs the golden tests the database recorded with it, and names the one that fails;
a forged claim of the engine's gate is shown as a MISMATCH. A release through `engine template
release` still shows its gate passed (design notes §10, threat model)."""
import json

import psycopg
import pytest
from helpers.roles import as_role
from psycopg import sql
from psycopg.types.json import Jsonb

COOLANT_ROW = 1800       # seed_templates/classes/spur.csv: cutcond 1, `"M8"` when coolant
COOLANT_OFF_ROW = 2900   # cutcond 2, `"M9"` when coolant: no seeded golden test reads it
TEST_NAME = "coolant_on_before_cutting"
GOLDEN_TEST = ("INSERT INTO template_test (gear_class, name, gear_id, expect) "
               "VALUES ('spur', %s, 42, ARRAY['line: M8'])")
EDIT = sql.SQL("UPDATE template_view SET {} = %s WHERE gear_class = 'spur' AND id = %s")
# The releaser's own call: the draft's version and hash, and results nobody ran.
BY_HAND = """
SELECT release_template(g.name, g.template_version, template_rows_hash(r.rows), %(tests)s, %(impact)s,
                        %(checks)s)
FROM gear_class g CROSS JOIN assembled_rows_of(ARRAY[g.name]) r WHERE g.name = 'spur'"""
FORGED = BY_HAND.replace("%(checks)s)", "%(checks)s, via => 'engine')")
INVENTED = {"tests": Jsonb([{"class": "spur", "name": name, "passed": True}
                            for name in (TEST_NAME, "gear42-climb", "gear42-header")]),
            "impact": Jsonb({"jobs": 1, "changed": 0}),
            "checks": Jsonb({"lint": "passed", "analysis": "no finding", "golden_tests": 3})}


def committed(url, statement, params=()):
    with psycopg.connect(url) as conn:
        conn.execute(statement, params)


def refused_draft(run):
    """spur with a golden test that wants M8 before cutting, and a draft emitting M9 instead: the
    engine's gate refuses it, naming the test."""
    committed(run.url, GOLDEN_TEST, (TEST_NAME,))
    committed(run.url, EDIT.format(sql.Identifier("o")), ('"M9"', COOLANT_ROW))
    refused = run("template", "release", "--class", "spur", "--yes")
    assert refused.exit_code == 1 and f"spur/{TEST_NAME}" in refused.stderr


def release_by_hand(url, statement=BY_HAND) -> None:
    with psycopg.connect(url) as conn, as_role(conn, "engine_releaser"):
        conn.execute(statement, INVENTED)


def released_v2(run) -> tuple[str, dict]:
    """The history's line of v2's release, and v2's release in --json."""
    text = run("template", "history", "--class", "spur")
    as_json = run("template", "history", "--class", "spur", "--json")
    assert text.exit_code == 0 and as_json.exit_code == 0
    lines = text.stdout.splitlines()
    line = lines[lines.index(next(line for line in lines if line.startswith("v2 "))) + 1]
    release = next(v for v in json.loads(as_json.stdout)["versions"] if v["version"] == 2)["release"]
    return line, release


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_release_by_hand_of_a_refused_draft_is_not_shown_as_passed(run):
    refused_draft(run)
    release_by_hand(run.url)
    line, release = released_v2(run)
    assert "gate passed" not in line
    assert "by hand from SQL" in line and "not through the engine's gate" in line
    assert f"re-checked now: fails: golden test spur/{TEST_NAME}" in line
    assert release["released_via"] == "sql" and release["gate"] == "not run"
    assert not release["recheck"]["passed"]
    assert any(f"spur/{TEST_NAME}" in problem for problem in release["recheck"]["problems"])


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_forged_claim_of_the_engines_gate_is_shown_as_a_mismatch(run):
    """The engine calls release_template as the same login: a releaser can name the engine too.
    The re-check, not the claim, decides what the screen says."""
    refused_draft(run)
    release_by_hand(run.url, FORGED)
    line, release = released_v2(run)
    assert "gate passed" not in line and line.split(": ", 1)[1].startswith("MISMATCH")
    assert f"spur/{TEST_NAME}" in line
    assert release["released_via"] == "engine" and release["gate"] == "mismatch"


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_the_recorded_tests_are_the_databases_not_the_callers(run):
    """A test deleted after the release is still re-run: the database recorded it with the release."""
    refused_draft(run)
    release_by_hand(run.url)
    committed(run.url, "DELETE FROM template_test WHERE gear_class = 'spur' AND name = %s", (TEST_NAME,))
    line, release = released_v2(run)
    assert f"spur/{TEST_NAME}" in line and not release["recheck"]["passed"]


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_release_through_the_engines_gate_shows_its_gate_passed(run):
    committed(run.url, GOLDEN_TEST, (TEST_NAME,))
    committed(run.url, EDIT.format(sql.Identifier("o")), ('"M9 ; COOLANT OFF"', COOLANT_OFF_ROW))
    released = run("template", "release", "--class", "spur", "--yes")
    assert released.exit_code == 0, released.stderr
    line, release = released_v2(run)
    assert "gate passed" in line and "by hand" not in line and "MISMATCH" not in line
    assert release["released_via"] == "engine" and release["gate"] == "passed" and release["recheck"]["passed"]
    with psycopg.connect(run.url) as conn:   # the gate runs the tests of spur and of its descendants
        gated = conn.execute("SELECT count(*) FROM template_test t "
                             "JOIN classes_and_below(ARRAY['spur']) b ON b.name = t.gear_class").fetchone()[0]
    assert release["recheck"]["tests"] == gated > 1


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_a_release_recorded_before_migration_0026_is_re_checked_with_the_tests_of_today(run):
    """A release stored before released_via and golden_tests existed (as the migration leaves it:
    'unrecorded', no tests) is not shown as the gate's; the class's tests now are re-run."""
    refused_draft(run)
    committed(run.url, "INSERT INTO template_release (gear_class, version, hash, role, tests, released_via) "
                       "SELECT g.name, g.template_version, template_rows_hash(r.rows), 'engine_releaser', %(tests)s, "
                       "'unrecorded' FROM gear_class g CROSS JOIN assembled_rows_of(ARRAY[g.name]) r "
                       "WHERE g.name = 'spur'", INVENTED)
    line, release = released_v2(run)
    assert "gate passed" not in line and "how it was released is not recorded" in line
    assert f"golden test spur/{TEST_NAME}" in line
    assert release["gate"] == "not run" and not release["recheck"]["recorded_tests"]


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_retired_release_is_re_checked_against_its_own_rows_not_the_ones_released_now(run):
    """v2 passed the gate; v3, broken, was then released by hand. v2's tests are re-run against
    v2's stored rows: it still passed, and v3 does not."""
    committed(run.url, GOLDEN_TEST, (TEST_NAME,))
    committed(run.url, EDIT.format(sql.Identifier("o")), ('"M9 ; COOLANT OFF"', COOLANT_OFF_ROW))
    assert run("template", "release", "--class", "spur", "--yes").exit_code == 0
    committed(run.url, EDIT.format(sql.Identifier("o")), ('"M9"', COOLANT_ROW))
    release_by_hand(run.url)
    versions = json.loads(run("template", "history", "--class", "spur", "--json").stdout)["versions"]
    gates = {v["version"]: (v["state"], v["release"]["gate"]) for v in versions if v["release"]}
    assert gates[2] == ("retired", "passed") and gates[3] == ("released", "not run")


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_forged_claim_that_passes_its_re_check_still_says_whose_word_the_impact_is(run):
    """Adversary, issue 26: a releaser names the engine by hand for a draft whose checks pass, with
    an invented impact (0 of 1 changed). The re-check cannot recompute the impact (it compared the
    draft with the programs stored then) nor tell the login's call from the engine's: the line
    says the gate passed as that login recorded it, and the impact is what the session stated."""
    committed(run.url, EDIT.format(sql.Identifier("o")), ('"M9 ; COOLANT OFF"', COOLANT_OFF_ROW))
    release_by_hand(run.url, FORGED)
    line, release = released_v2(run)
    assert release["released_via"] == "engine" and release["gate"] == "passed"
    assert "gate passed (as " in line and " recorded it; re-checked now:" in line
    assert "impact as the releasing session stated it (not re-checked): 0 of 1 stored job(s) changed" in line
