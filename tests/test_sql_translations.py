"""SQL-style conditions are translated once and kept (issue 12): a seeded gear is instantiated
without loading sqlglot, a condition edited in SQL still runs (translated when used) and gets
its translation kept by `engine lint`, and a stored translation is checked like any expression."""
import json
import subprocess
import sys

import psycopg
import pytest

from engine.templates.expressions import translated_python
from engine.templates.translations import text_hash

PROBE = """
import sys, json
from engine.cli import main
try:
    main(["--database-url", sys.argv[1], "instantiate", "--gear", sys.argv[2], "--json", *sys.argv[3:]])
except SystemExit as done:
    print(json.dumps({"exit": done.code, "sqlglot": "sqlglot" in sys.modules}), file=sys.stderr)
"""


def instantiated_in_a_new_process(url: str, gear: int, *options: str) -> dict:
    done = subprocess.run([sys.executable, "-c", PROBE, url, str(gear), *options], capture_output=True, text=True,
                          timeout=120)
    return json.loads(done.stderr.strip().splitlines()[-1])


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_seeded_classes_run_from_their_kept_translations_without_sqlglot(fresh_database_url):
    for gear in (42, 53):     # spur: `shift_per_part = 0`; worm wheel: `cut_on AND NOT tangential` …
        assert instantiated_in_a_new_process(fresh_database_url, gear) == {"exit": 0, "sqlglot": False}


def test_kept_translations_are_the_seeded_conditions_in_python(conn):
    kept = {sql: (digest, python) for digest, sql, python in
            conn.execute("SELECT text_hash, sql, python FROM sql_translation")}
    # the worm wheel's rows per dialect (issue 30): an AND whose NOT is deferred like its other terms
    assert kept["dialect = '840d' AND NOT tangential"][1] == \
        "_sql_and(_sql_eq(dialect, '840d'), _sql_defer('_sql_not', tangential))"
    assert kept["shift_per_part = 0"][1] == "_sql_eq(shift_per_part, 0)"
    assert kept["fanuc AND cut_on AND NOT tangential"][1] == \
        "_sql_and(fanuc, cut_on, _sql_defer('_sql_not', tangential))"
    assert all(digest == text_hash(sql) for sql, (digest, _) in kept.items())


def test_no_engine_role_may_write_a_translation(conn):
    for role in ("engine_runner", "engine_editor"):
        with pytest.raises(psycopg.errors.InsufficientPrivilege), conn.transaction():
            conn.execute(f"SET LOCAL ROLE {role}")
            conn.execute("INSERT INTO sql_translation (text_hash, sql, python) "
                         "VALUES ('x', 'coolant AND 1 = 1', 'True')")


def test_lint_names_a_translation_that_is_not_sqlglot_s(run):
    with psycopg.connect(run.url) as conn:
        conn.execute("INSERT INTO sql_translation (text_hash, sql, python) VALUES (%s, 'coolant AND 1 = 1', 'True')",
                     (text_hash("coolant AND 1 = 1"),))
        conn.execute("UPDATE template_view SET p_emit = 'coolant AND 1 = 1' WHERE gear_class = 'spur' AND id = 1800")
    linted = run("lint")
    assert linted.exit_code == 1
    assert "class spur row 1800 column p_emit: its stored translation (table sql_translation) is not sqlglot's" \
        in linted.stdout


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_condition_edited_in_sql_runs_and_lint_keeps_its_translation(run):
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE template_view SET p_emit = 'coolant AND 1 = 1' WHERE gear_class = 'spur' AND id = 1800")
    made = run("instantiate", "--gear", "42", "--no-coolant", "--draft")   # the editor tries the edited draft
    assert made.exit_code == 0 and "\nM8\n" not in made.stdout
    assert instantiated_in_a_new_process(run.url, 42, "--draft")["sqlglot"] is True      # translated when used
    assert run("lint").exit_code == 0
    with psycopg.connect(run.url) as conn:
        assert conn.execute("SELECT python FROM sql_translation WHERE sql = 'coolant AND 1 = 1'").fetchone() \
            == (translated_python("coolant AND 1 = 1"),)
    assert instantiated_in_a_new_process(run.url, 42, "--draft") == {"exit": 0, "sqlglot": False}


def test_a_tampered_translation_is_refused_by_the_gate(run):
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE sql_translation SET python = 'open(\"/etc/passwd\")' "
                     "WHERE sql = 'shift_per_part = 0'")
    refused = run("instantiate", "--gear", "42")
    assert refused.exit_code == 1 and refused.stderr.count("\n") == 1
    assert "open() is not available" in refused.stderr and "row 1310" in refused.stderr
