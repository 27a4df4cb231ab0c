"""The version and hash a program records always equal the rows it was made from, whatever route
edited the template (issue 13, design notes §10): templates change only through template_view or
the engine, which version and audit; editors have no other write; what changes rows without a
version is refused at commit; the audit names the login person and the role and is written by
nobody's hand."""
from __future__ import annotations

import re
import threading

import psycopg
import pytest
from helpers.roles import as_role, logins
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from psycopg import errors
from psycopg.types.json import Jsonb

from engine.cli.app import main
from engine.library import refactor as refactoring
from engine.library.nc_import import import_nc
from engine.nc.lineage import without_lineage
from engine.programs.instantiate import instantiate_gear
from engine.programs.options import RunMode
from engine.programs.records import Planned
from engine.programs.storage import store_one
from engine.templates.decision_table import CompiledTemplate
from engine.templates.history import restore
from engine.templates.rows import Template, TemplateRow, rows_hash
from engine.templates.store import load_template, replace_template
from engine.templates.template_csv import export_csv
from engine.templates.versions import draft_template


@pytest.fixture
def login_in(server_url):
    with logins(server_url) as create:
        yield create


def versions(conn, *names):
    return [conn.execute("SELECT template_version FROM gear_class WHERE name = %s", (name,)).fetchone()[0]
            for name in names]


def audit_rows(conn, gear_class):
    return conn.execute("SELECT changed_by, login, row_id, operation FROM template_audit WHERE gear_class = %s "
                        "ORDER BY id", (gear_class,)).fetchall()


def version_rows(conn, gear_class, version):
    rows = conn.execute("SELECT rows FROM template_version_rows WHERE gear_class = %s AND version = %s",
                        (gear_class, version)).fetchone()[0]
    return tuple(TemplateRow(**row) for row in rows)


# --- editors write templates only through the view and the engine ---------------------------------

FORBIDDEN = [
    "UPDATE component SET o = '\"G0 X9999\"' WHERE id = (SELECT component_id FROM assembly "
    "WHERE gear_class = 'spur' AND id = 800)",
    "INSERT INTO component (t, o) VALUES ('main', '\"G0 X9999\"')",
    "DELETE FROM assembly WHERE gear_class = 'spur' AND id = 800",
    "UPDATE assembly SET component_id = (SELECT component_id FROM assembly WHERE gear_class = 'helical' AND id = 1400) "
    "WHERE gear_class = 'spur' AND id = 1400",
    "INSERT INTO assembly (gear_class, id, component_id) SELECT 'spur', 801, component_id FROM assembly "
    "WHERE gear_class = 'spur' AND id = 800",
    "UPDATE gear_class SET template_version = template_version - 1 WHERE name = 'spur'",
    "INSERT INTO gear_class (name, template_version) VALUES ('records_forged', 7)",
    "INSERT INTO template_audit (gear_class, row_id, operation, new) VALUES ('spur', 800, 'INSERT', '{}')",
    "SELECT audit_class_change('spur', '{}')",
    "SELECT bump_template_versions('spur')",
    "SELECT store_current_version('spur')",
    "INSERT INTO template_change (xact, gear_class, bumped) VALUES (pg_current_xact_id(), 'spur', true)",
    "INSERT INTO template_version_rows (gear_class, version, rows) VALUES ('spur', 99, '[]')",
]


@pytest.mark.parametrize("statement", FORBIDDEN, ids=[s[:50] for s in FORBIDDEN])
def test_an_editor_has_no_write_but_the_view_and_the_engines_functions(conn, statement):
    before = conn.execute("SELECT * FROM template_view ORDER BY gear_class, id").fetchall()
    with pytest.raises(errors.InsufficientPrivilege), conn.transaction(), as_role(conn, "engine_editor"):
        conn.execute(statement)
    assert conn.execute("SELECT * FROM template_view ORDER BY gear_class, id").fetchall() == before


def test_a_preset_bump_marker_does_not_skip_the_version(conn):
    before = versions(conn, "spur", "duplex")
    with as_role(conn, "engine_editor"):
        for name in ("engine_bumped.spur", "engine_bumped.duplex"):
            conn.execute("SELECT set_config(%s, pg_current_xact_id()::text, true)", (name,))
        conn.execute("UPDATE template_view SET o = '\"G90 G71 G94 ; PRESET\"' WHERE gear_class = 'spur' AND id = 800")
    assert versions(conn, "spur", "duplex") == [before[0] + 1, before[1] + 1]


def test_reparenting_is_versioned_and_audited_for_the_class_and_below(conn):
    before = versions(conn, "spur", "duplex", "helical")
    with as_role(conn, "engine_editor"):
        conn.execute("INSERT INTO gear_class (name, parent) VALUES ('records_base', 'cylindrical')")
        conn.execute("INSERT INTO template_view (gear_class, id, t, o) VALUES ('records_base', 750, 'main', "
                     "'\"; SHOP STANDARD\"')")
        conn.execute("UPDATE gear_class SET parent = 'records_base' WHERE name = 'spur'")
    assert versions(conn, "spur", "duplex", "helical") == [before[0] + 1, before[1] + 1, before[2]]
    assert audit_rows(conn, "spur")[-1] == ("engine_editor", conn.info.user, 750, "INSERT")
    # spur's draft, tried by the editor
    assert "; SHOP STANDARD" in instantiate_gear(conn, 42, mode=RunMode(draft=True)).lines


def test_a_class_cannot_derive_from_itself_or_below_itself(conn):
    with pytest.raises(errors.CheckViolation, match="spur cannot derive from duplex"), conn.transaction(), \
            as_role(conn, "engine_editor"):
        conn.execute("UPDATE gear_class SET parent = 'duplex' WHERE name = 'spur'")



def ancestors(conn, name):
    """How many classes lie above `name`, walked in Python (not the database's capped recursion)."""
    count, parent = 0, conn.execute("SELECT parent FROM gear_class WHERE name = %s", (name,)).fetchone()[0]
    while parent is not None:
        count, parent = count + 1, conn.execute("SELECT parent FROM gear_class WHERE name = %s",
                                                (parent,)).fetchone()[0]
    return count


def test_no_class_lies_deeper_than_the_lineage_the_templates_follow(conn):
    """Assembling stops 50 classes up: a class deeper would lose its far ancestors' rows, and a
    re-parent past that depth could close a cycle."""
    with as_role(conn, "engine_editor"):
        conn.execute("INSERT INTO template_view (gear_class, id, t, o) VALUES ('spur', 750, 'main', '\"; TOP\"')")
        chain = ["spur"]
        while ancestors(conn, chain[-1]) < 50:
            chain.append(f"records_zc{len(chain)}")
            conn.execute("INSERT INTO gear_class (name, parent) VALUES (%s, %s)", chain[-2:][::-1])
        assembled = dict(conn.execute("SELECT * FROM assembled_rows_of(%s)", (["spur", chain[-1]],)).fetchall())
        assert '"; TOP"' in [row["o"] for row in assembled[chain[-1]]] and assembled[chain[-1]] == assembled["spur"]
        for statement, params in [("INSERT INTO gear_class (name, parent) VALUES ('records_deeper', %s)", (chain[-1],)),
                                  ("UPDATE gear_class SET parent = %s WHERE name = %s", (chain[-1], chain[1])),
                                  ("UPDATE gear_class SET parent = %s WHERE name = 'duplex'", (chain[-1],))]:
            with pytest.raises(errors.CheckViolation,
                               match="cannot derive|at most 50 classes above"), conn.transaction():
                conn.execute(statement, params)
    assert ancestors(conn, chain[-1]) == 50 and ancestors(conn, "duplex") == ancestors(conn, "spur") + 1


def blocked(url, pid, worker):
    """Whether backend `pid` waits for a lock, polled while its worker runs (False once it ended)."""
    with psycopg.connect(url, autocommit=True) as watcher:
        while worker.is_alive():
            if watcher.execute("SELECT wait_event_type = 'Lock' FROM pg_stat_activity WHERE pid = %s",
                               (pid,)).fetchone()[0]:
                return True
            watcher.execute("SELECT pg_sleep(0.05)")
    return False


def test_two_reparents_in_parallel_never_commit_a_cycle(fresh_database_url):
    with psycopg.connect(fresh_database_url, autocommit=True) as setup:
        setup.execute("INSERT INTO gear_class (name, parent) VALUES ('records_ra', 'spur'), ('records_rb', 'spur')")
    refused = []
    with psycopg.connect(fresh_database_url) as first, psycopg.connect(fresh_database_url) as second:
        first.execute("UPDATE gear_class SET parent = 'records_rb' WHERE name = 'records_ra'")

        def reparent_the_other():
            try:
                second.execute("UPDATE gear_class SET parent = 'records_ra' WHERE name = 'records_rb'")
                second.commit()
            except psycopg.Error as error:
                refused.append(error)
        worker = threading.Thread(target=reparent_the_other)
        worker.start()
        assert blocked(fresh_database_url, second.info.backend_pid, worker)
        first.commit()
        worker.join()
    assert isinstance(refused[0], errors.CheckViolation) and "derive from records_ra" in str(refused[0])
    with psycopg.connect(fresh_database_url) as check:
        assert ancestors(check, "records_ra") == ancestors(check, "spur") + 2


# --- at commit: rows equal the rows stored for the version -----------------------------------------

def commit_refused(url, *statements):
    """Run the statements as the owner; the commit must be refused. The message."""
    with psycopg.connect(url) as conn:
        for statement in statements:
            conn.execute(statement)
        with pytest.raises(errors.IntegrityConstraintViolation) as refused:
            conn.commit()
    return refused.value.diag.message_primary


def test_a_direct_write_that_changes_rows_without_a_version_is_refused_at_commit(fresh_database_url):
    with psycopg.connect(fresh_database_url) as conn:
        before = export_csv(load_template(conn, "spur")), versions(conn, "spur")
    message = commit_refused(fresh_database_url, "UPDATE component SET o = '\"G0 X9999\"' WHERE id = (SELECT "
                             "component_id FROM assembly WHERE gear_class = 'spur' AND id = 800)")
    assert re.search(r"class \w+: its template rows differ from those stored for its version", message)
    assert "edit templates through template_view or the engine" in message
    with psycopg.connect(fresh_database_url) as conn:
        assert (export_csv(load_template(conn, "spur")), versions(conn, "spur")) == before


def test_a_version_set_back_is_refused_at_commit(fresh_database_url):
    with psycopg.connect(fresh_database_url) as conn:
        conn.execute("UPDATE template_view SET o = '\"G90 G71 G94 ; V2\"' WHERE gear_class = 'spur' AND id = 800")
        conn.commit()
    message = commit_refused(fresh_database_url,
                             "UPDATE gear_class SET template_version = template_version - 1 WHERE name = 'spur'")
    assert "class spur:" in message and "version" in message


def test_a_refactor_that_changed_a_class_would_be_refused_at_commit(fresh_database_url, monkeypatch):
    """Even with its own invariant check gone, a refactor that re-points a row to another body
    (a bug) cannot commit."""
    monkeypatch.setattr(refactoring, "check_invariants", lambda conn, snapshot: None)
    monkeypatch.setattr(refactoring, "REPOINT_DUPLICATES", """
        UPDATE assembly SET component_id = (SELECT component_id FROM assembly WHERE gear_class = 'helical'
                                            AND id = 1400)
        WHERE gear_class = 'spur' AND id = 1400""")
    with psycopg.connect(fresh_database_url) as conn:
        before = export_csv(load_template(conn, "spur"))
        conn.commit()   # the refactor's transaction is the connection's own: it commits
        with pytest.raises(errors.IntegrityConstraintViolation, match=r"class \w+: its template rows differ"):
            refactoring.refactor(conn)
        conn.rollback()
        assert export_csv(load_template(conn, "spur")) == before


def test_a_stored_version_is_the_class_as_it_was_and_stays_so(conn):
    """Not even the owner stores other rows under a version, or changes or drops one; a class
    without programs still goes with its history."""
    version = versions(conn, "spur")[0]
    refusals = [("INSERT INTO template_version_rows (gear_class, version, rows) VALUES ('spur', %s, '[]')"
                 % (version + 1), errors.IntegrityConstraintViolation),
                ("UPDATE template_version_rows SET rows = '[]' WHERE gear_class = 'spur'",
                 errors.InsufficientPrivilege),
                ("DELETE FROM template_version_rows WHERE gear_class = 'spur'", errors.InsufficientPrivilege),
                ("TRUNCATE template_version_rows CASCADE", errors.InsufficientPrivilege)]
    for statement, error in refusals:
        with pytest.raises(error), conn.transaction():
            conn.execute(statement)
    def stored_versions():
        return dict(conn.execute("SELECT gear_class, count(*) FROM template_version_rows "
                                 "WHERE gear_class IN ('spur', 'records_gone') GROUP BY 1").fetchall())
    before = stored_versions()
    conn.execute("INSERT INTO gear_class (name) VALUES ('records_gone')")
    conn.execute("SET CONSTRAINTS template_rows_match_version IMMEDIATE")   # stores its version 0 now
    assert stored_versions() == {**before, "records_gone": 1}
    conn.execute("DELETE FROM gear_class WHERE name = 'records_gone'")
    assert stored_versions() == before


# --- the audit --------------------------------------------------------------------------------------

def test_the_audit_names_the_login_person_and_the_role_on_every_route(database_url, login_in):
    login = login_in("engine_editor")
    with psycopg.connect(login.url(database_url)) as conn:
        conn.execute("SET ROLE engine_editor")
        conn.execute("UPDATE template_view SET o = '\"G90 G71 G94 ; VIEW\"' WHERE gear_class = 'spur' AND id = 800")
        rows = [r if r.id != 900 else TemplateRow(r.id, r.t, r.n, r.p_calc, r.s, '"; IMPORT"', r.p_emit)
                for r in load_template(conn, "spur").rows]
        replace_template(conn, "spur", rows)
        conn.execute("INSERT INTO gear_class (name, parent) VALUES ('records_base', 'cylindrical')")
        conn.execute("INSERT INTO template_view (gear_class, id, t, o) VALUES ('records_base', 750, 'main', '\"; B\"')")
        conn.execute("UPDATE gear_class SET parent = 'records_base' WHERE name = 'spur'")   # re-parented
        audited = audit_rows(conn, "spur")[-3:]
        conn.rollback()
    assert audited == [("engine_editor", login.name, 800, "UPDATE"), ("engine_editor", login.name, 900, "UPDATE"),
                       ("engine_editor", login.name, 750, "INSERT")]


def test_who_and_when_of_an_audit_row_are_stamped_and_it_is_never_changed(conn):
    conn.execute("INSERT INTO template_audit (changed_by, login, changed_at, gear_class, row_id, operation, new) "
                 "VALUES ('someone else', 'nobody', now() - interval '1 year', 'spur', 1, 'INSERT', '{}')")
    assert conn.execute("SELECT changed_by, login, changed_at = now() FROM template_audit ORDER BY id DESC "
                        "LIMIT 1").fetchone() == (conn.info.user, conn.info.user, True)
    for statement in ("UPDATE template_audit SET changed_by = 'someone else'", "DELETE FROM template_audit",
                      "TRUNCATE template_audit"):
        with pytest.raises(errors.InsufficientPrivilege, match="records"), conn.transaction():
            conn.execute(statement)


# --- every route: the version and hash a program records are the rows it was made from ---------------

def program_matches_its_version(conn, program_id):
    """The program's lines are what its stored version's rows make of its job, and its hash is
    the hash of those rows (computed by the engine, not by the SQL that stored it)."""
    gear_class, version, digest, lines, row_ids, params, module_params = conn.execute(
        "SELECT p.gear_class, p.template_version, p.template_hash, p.lines, p.row_ids, j.params, j.module_params "
        "FROM program p JOIN job j ON j.id = p.job_id WHERE p.id = %s", (program_id,)).fetchone()
    rows = version_rows(conn, gear_class, version)
    made = CompiledTemplate(Template(gear_class, version, rows)).run(params, module_params).lines
    return rows_hash(rows) == digest and made == without_lineage(lines, row_ids)


NC_PROGRAM = "%\nO1000\nG0 X{x} Z2\nG1 Z-10 F0.2\nM30\n%\n"


def store_nc_program(conn, gear_class):
    """An imported class has no model: its job is written by hand and its program made the way
    the engine makes one (decision table, then storage with its lineage line), from the draft the
    import made (the editor trying it)."""
    template = draft_template(conn, gear_class)
    result = CompiledTemplate(template).run({})
    job = conn.execute("INSERT INTO job (gear_class, machine, params) VALUES (%s, 'lathe-iso', '{\"program_name\": "
                       "\"NC\"}') RETURNING id", (gear_class,)).fetchone()[0]
    planned = Planned(None, gear_class, "lathe-iso", None, {"program_name": "NC"}, {}, template, result)
    return store_one(conn, planned, job, None).program_id


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_every_route_of_an_edit_keeps_each_programs_version_equal_to_its_rows(fresh_database_url, tmp_path):
    url, made = fresh_database_url, []
    nc_file = tmp_path / "part.nc"

    def step(edit):
        with psycopg.connect(url) as conn:
            edit(conn)
            conn.commit()
            made.append(instantiate_gear(conn, 42, mode=RunMode(draft=True)).program_id)   # the editor tries each edit
            conn.commit()

    def import_part(conn, x):
        nc_file.write_text(NC_PROGRAM.format(x=x))
        import_nc(conn, nc_file, "records_part")
        made.append(store_nc_program(conn, "records_part"))

    step(lambda conn: None)
    step(lambda conn: conn.execute("UPDATE template_view SET o = '\"G90 G71 G94 ; VIEW\"' WHERE gear_class = 'spur' "
                                   "AND id = 800"))
    step(lambda conn: replace_template(conn, "spur", [
        r if r.id != 500 else TemplateRow(r.id, r.t, r.n, r.p_calc, r.s, '"; IMPORTED"', r.p_emit)
        for r in load_template(conn, "spur").rows]))
    step(lambda conn: restore(conn, "spur", 1))
    step(lambda conn: (conn.execute("INSERT INTO gear_class (name, parent) VALUES ('records_base', 'cylindrical')"),
                       conn.execute("INSERT INTO template_view (gear_class, id, t, o) VALUES ('records_base', 750, "
                                    "'main', '\"; BASE\"')"),
                       conn.execute("UPDATE gear_class SET parent = 'records_base' WHERE name = 'spur'")))
    step(lambda conn: (conn.execute("WITH copy AS (INSERT INTO component (t, o, p_calc, s, p_emit) SELECT t, o, "
                                    "p_calc, s, p_emit FROM component WHERE id = (SELECT component_id FROM assembly "
                                    "WHERE gear_class = 'spur' AND id = 1400) RETURNING id) UPDATE assembly SET "
                                    "component_id = (SELECT id FROM copy) WHERE gear_class = 'spur' AND id = 1400"),
                       conn.commit(), refactoring.refactor(conn)))
    step(lambda conn: import_part(conn, 10))
    step(lambda conn: import_part(conn, 20))   # import-nc into the class it made
    with psycopg.connect(url) as conn:
        recorded = conn.execute("SELECT DISTINCT gear_class, template_version FROM program").fetchall()
        assert len(recorded) == 7 and all(program_matches_its_version(conn, program_id) for program_id in made)
        assert conn.execute("SELECT count(*) FROM template_audit WHERE gear_class = 'spur'").fetchone()[0] > 0


def test_an_editor_login_runs_the_engines_imports_without_table_rights(fresh_database_url, login_in, tmp_path):
    from click.testing import CliRunner

    url = login_in("engine_editor").url(fresh_database_url)
    csv_file, nc_file = tmp_path / "spur.csv", tmp_path / "part.nc"
    with psycopg.connect(url) as conn:
        csv_file.write_text(export_csv(load_template(conn, "spur")).replace('"G90 G71 G94"', '"G90 G71 G94 ; CSV"'))
    nc_file.write_text(NC_PROGRAM.format(x=10))

    def engine(*args):
        result = CliRunner().invoke(main, ["--database-url", url, *args])
        assert result.exit_code == 0, result.output
    engine("template", "import", "--class", "spur", str(csv_file))
    engine("template", "restore", "--class", "spur", "--version", "1")
    engine("import-nc", str(nc_file), "--class", "records_part")
    nc_file.write_text(NC_PROGRAM.format(x=20))
    engine("import-nc", str(nc_file), "--class", "records_part")
    with psycopg.connect(url) as conn:
        assert versions(conn, "spur", "records_part") == [3, 2]
        assert {row[:2] for row in audit_rows(conn, "spur")[-2:]} == {(conn.info.user, conn.info.user)}


# --- the hash: the database's and the engine's agree on every text ------------------------------------

texts = st.none() | st.text(st.characters(blacklist_characters="\x00", blacklist_categories=("Cs",)), max_size=40)
rows = st.lists(st.builds(TemplateRow, st.integers(0, 2**31 - 1), st.sampled_from(["main", "prep", "sync"]),
                          st.integers(0, 1000), texts, texts, texts, texts), max_size=6)


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(rows=rows)
def test_the_databases_template_hash_is_the_engines(conn, rows):
    as_json = Jsonb([{"id": r.id, "t": r.t, "n": r.n, "p_calc": r.p_calc, "s": r.s, "o": r.o, "p_emit": r.p_emit}
                     for r in rows])
    assert conn.execute("SELECT template_rows_hash(%s)", (as_json,)).fetchone()[0] == rows_hash(rows)


def test_every_stored_version_hashes_as_the_engine_hashes_its_rows(conn):
    for gear_class, version, digest in conn.execute("SELECT gear_class, version, hash FROM template_version_rows"):
        assert digest == rows_hash(version_rows(conn, gear_class, version)), (gear_class, version)
