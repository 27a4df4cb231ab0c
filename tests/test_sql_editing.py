"""Editing templates in SQL (issue 6, design notes §10): INSERT, UPDATE, DELETE on
template_view with copy-on-write for shared and inherited rows, the obvious problems refused
by the database, versions, template_audit, and the roles engine_reader, engine_runner,
engine_editor."""

import psycopg
import pytest
from helpers.releases import release_draft
from helpers.roles import as_role
from psycopg import errors, sql
from psycopg.types.json import Jsonb

from engine.library.refactor import refactor
from engine.programs.instantiate import instantiate_gear
from engine.programs.options import RunMode
from engine.templates.rows import TemplateRow
from engine.templates.store import load_template, replace_template
from engine.templates.template_csv import export_csv

ROW_COLUMNS = ("id", "t", "n", "p_calc", "s", "o", "p_emit")




def exported(conn, gear_class):
    return export_csv(load_template(conn, gear_class))


def view_row(conn, gear_class, row_id):
    return conn.execute("SELECT id, t, n, p_calc, s, o, p_emit, shared_by, inherited_from FROM template_view "
                        "WHERE gear_class = %s AND id = %s", (gear_class, row_id)).fetchone()


def own_component(conn, gear_class, row_id):
    found = conn.execute("SELECT component_id FROM assembly WHERE gear_class = %s AND id = %s",
                         (gear_class, row_id)).fetchone()
    return found and found[0]


def count(conn, table):
    return conn.execute(sql.SQL("SELECT count(*)::int FROM {}").format(sql.Identifier(table))).fetchone()[0]


def versions(conn):
    return dict(conn.execute("SELECT name, template_version FROM gear_class").fetchall())


def shared_row(conn, a, b):
    """A row id both classes own with the same component (a body stored once, used by both)."""
    return conn.execute("""
        SELECT x.id FROM assembly x JOIN assembly y ON y.component_id = x.component_id AND y.id = x.id
        JOIN component c ON c.id = x.component_id
        WHERE x.gear_class = %s AND y.gear_class = %s AND c.o IS NOT NULL AND c.s IS NULL
        ORDER BY x.id LIMIT 1""", (a, b)).fetchone()[0]


def state(conn):
    """Everything an edit may change: every class's template, versions, components, audit."""
    return (conn.execute("SELECT * FROM template_view ORDER BY gear_class, id").fetchall(), versions(conn),
            count(conn, "component"), count(conn, "template_audit"))


# --- copy-on-write --------------------------------------------------------------------------

def test_updating_a_shared_row_changes_only_the_class_named(conn):
    row_id = shared_row(conn, "spur", "helical")
    helical_before, taper_before = exported(conn, "helical"), exported(conn, "taper")
    shared_before = view_row(conn, "spur", row_id)[7]
    old_component = own_component(conn, "spur", row_id)
    components = count(conn, "component")

    updated = conn.execute("UPDATE template_view SET o = %s WHERE gear_class = 'spur' AND id = %s",
                           ('"G90 G71 G94 ; SPUR ONLY"', row_id)).rowcount

    assert updated == 1
    assert view_row(conn, "spur", row_id)[5] == '"G90 G71 G94 ; SPUR ONLY"'
    assert exported(conn, "helical") == helical_before          # byte-identical
    assert exported(conn, "taper") == taper_before
    assert own_component(conn, "helical", row_id) == old_component   # the shared component is untouched
    assert own_component(conn, "spur", row_id) != old_component
    # spur and duplex (which inherits spur's row) use the new body; the others keep the old one
    assert view_row(conn, "spur", row_id)[7] == 2
    assert view_row(conn, "helical", row_id)[7] == shared_before - 2
    assert count(conn, "component") == components + 1


def test_a_body_already_stored_is_reused_and_an_unused_one_deleted(conn):
    spur_row, helical_row = 600, 700
    helical_body = view_row(conn, "helical", helical_row)
    assert view_row(conn, "spur", spur_row)[5] != helical_body[5]
    target = own_component(conn, "helical", helical_row)
    components = count(conn, "component")

    conn.execute("UPDATE template_view SET t = %s, p_calc = %s, s = %s, o = %s, p_emit = %s "
                 "WHERE gear_class = 'spur' AND id = %s", (*helical_body[1:2], *helical_body[3:7], spur_row))
    assert own_component(conn, "spur", spur_row) == target     # stored once: the existing component
    assert count(conn, "component") == components

    # a body only spur used: changing it leaves no unused component behind
    conn.execute("UPDATE template_view SET o = '\"; ONE OFF\"' WHERE gear_class = 'spur' AND id = %s", (spur_row,))
    one_off = own_component(conn, "spur", spur_row)
    conn.execute("UPDATE template_view SET o = '\"; TWO OFF\"' WHERE gear_class = 'spur' AND id = %s", (spur_row,))
    assert conn.execute("SELECT 1 FROM component WHERE id = %s", (one_off,)).fetchone() is None
    assert count(conn, "component") == components + 1


def test_updating_an_inherited_row_adds_an_own_row_for_the_derived_class(conn):
    spur_before = exported(conn, "spur")
    assert view_row(conn, "duplex", 300)[8] == "spur"
    assert own_component(conn, "duplex", 300) is None

    conn.execute("UPDATE template_view SET o = 'f\"; GEAR {gear_id} DUPLEX\"' WHERE gear_class = 'duplex' AND id = 300")

    assert view_row(conn, "duplex", 300)[5] == 'f"; GEAR {gear_id} DUPLEX"'
    assert view_row(conn, "duplex", 300)[8] == "duplex"
    assert own_component(conn, "duplex", 300) is not None
    assert exported(conn, "spur") == spur_before

    # set back to exactly what spur gives: the own row goes, the row is inherited again
    spur_row = view_row(conn, "spur", 300)
    conn.execute("UPDATE template_view SET o = %s WHERE gear_class = 'duplex' AND id = 300", (spur_row[5],))
    assert own_component(conn, "duplex", 300) is None
    assert view_row(conn, "duplex", 300)[8] == "spur"


def test_an_inherited_row_cannot_be_deleted_from_a_derived_class(conn):
    before = state(conn)
    with pytest.raises(errors.RestrictViolation) as refused, conn.transaction():
        conn.execute("DELETE FROM template_view WHERE gear_class = 'duplex' AND id = 400")
    message = refused.value.diag.message_primary
    assert message == ("class duplex row 400: the row is inherited from spur; "
                       "an inherited row cannot be deleted from a derived class")
    assert "delete it from spur" in refused.value.diag.message_hint
    assert "override it in duplex with an UPDATE" in refused.value.diag.message_hint
    assert state(conn) == before


def test_insert_adds_an_own_row_and_delete_removes_it(conn):
    components, spur_before = count(conn, "component"), exported(conn, "spur")
    conn.execute("INSERT INTO template_view (gear_class, id, t, o, p_emit) "
                 "VALUES ('spur', 850, 'main', '\"; INSERTED\"', '  ')")
    row = view_row(conn, "spur", 850)
    assert row[:7] == (850, "main", 1, None, None, '"; INSERTED"', None)   # n defaults to 1, blank is absent
    assert view_row(conn, "duplex", 850)[8] == "spur"                      # derived classes inherit it
    assert count(conn, "component") == components + 1

    deleted = conn.execute("DELETE FROM template_view WHERE gear_class = 'spur' AND id = 850").rowcount
    assert deleted == 1
    assert view_row(conn, "spur", 850) is None and view_row(conn, "duplex", 850) is None
    assert count(conn, "component") == components
    assert exported(conn, "spur") == spur_before


def test_deleting_an_own_row_of_a_derived_class_brings_back_the_inherited_row(conn):
    spur_row = view_row(conn, "spur", 300)
    conn.execute("UPDATE template_view SET o = '\"; MINE\"' WHERE gear_class = 'duplex' AND id = 300")
    conn.execute("DELETE FROM template_view WHERE gear_class = 'duplex' AND id = 300")
    assert view_row(conn, "duplex", 300)[:7] == spur_row[:7]
    assert view_row(conn, "duplex", 300)[8] == "spur"


def test_id_and_n_of_an_own_row_may_change(conn):
    body = view_row(conn, "spur", 800)
    conn.execute("UPDATE template_view SET id = 850, n = 2 WHERE gear_class = 'spur' AND id = 800")
    assert view_row(conn, "spur", 800) is None
    assert view_row(conn, "spur", 850)[:7] == (850, body[1], 2, *body[3:7])


# --- versions ---------------------------------------------------------------------------------

def test_an_edit_bumps_the_version_of_the_class_and_of_the_classes_below_it_only(conn):
    before = versions(conn)
    conn.execute("UPDATE template_view SET o = o || ' + \" ; EDITED\"' WHERE gear_class = 'spur' AND id IN (800, 1100)")
    after = versions(conn)
    # one transaction, one version, however many rows it changes
    assert after["spur"] == before["spur"] + 1
    assert after["duplex"] == before["duplex"] + 1        # derives from spur
    assert {name: v for name, v in after.items() if name not in ("spur", "duplex")} == \
           {name: v for name, v in before.items() if name not in ("spur", "duplex")}
    assert load_template(conn, "spur").version == after["spur"]


def test_an_edit_of_a_derived_class_does_not_bump_its_parent(conn):
    before = versions(conn)
    conn.execute("UPDATE template_view SET n = 3 WHERE gear_class = 'duplex' AND id = 300")
    after = versions(conn)
    assert after["duplex"] == before["duplex"] + 1
    assert after["spur"] == before["spur"]


def test_an_update_that_changes_nothing_is_no_change(conn):
    before = state(conn)
    conn.execute("UPDATE template_view SET o = o, n = n WHERE gear_class = 'spur'")
    assert state(conn) == before


def test_a_program_records_the_version_the_edit_made(conn):
    before = versions(conn)["spur"]
    conn.execute("UPDATE template_view SET o = '\"G90 G71 G94 ; V\"' WHERE gear_class = 'spur' AND id = 800")
    program = instantiate_gear(conn, 42, mode=RunMode(draft=True))   # the editor tries the edit
    assert program.template_version == before + 1 == versions(conn)["spur"]
    assert '"G90 G71 G94 ; V"'.strip('"') in program.lines


# --- refusals ---------------------------------------------------------------------------------

REFUSALS = [
    ("unknown module type",
     "INSERT INTO template_view (gear_class, id, t, o) VALUES ('spur', 851, 'mian', '\"G90\"')",
     errors.CheckViolation,
     "class spur row 851 column t: unknown module type 'mian'; use one of main, prep, sync, shift, cutcond, cutmotion"),
    ("empty row",
     "UPDATE template_view SET o = NULL, s = ' ' WHERE gear_class = 'spur' AND id = 800",
     errors.CheckViolation, "class spur row 800 column o: row has neither o nor s: it does nothing"),
    ("p_calc without s",
     "INSERT INTO template_view (gear_class, id, t, p_calc, o) VALUES ('spur', 851, 'main', 'x > 1', '\"G90\"')",
     errors.CheckViolation,
     "class spur row 851 column p_calc: p_calc has no effect without s (use p_emit to decide output)"),
    ("duplicate id on insert",
     "INSERT INTO template_view (gear_class, id, t, o) VALUES ('spur', 800, 'main', '\"G90\"')",
     errors.UniqueViolation, "class spur row 800 column id: the class already has row 800 (its own)"),
    ("insert over an inherited row",
     "INSERT INTO template_view (gear_class, id, t, o) VALUES ('duplex', 800, 'main', '\"G90\"')",
     errors.UniqueViolation, "class duplex row 800 column id: the class already has row 800 (inherited from spur)"),
    ("duplicate id on update",
     "UPDATE template_view SET id = 900 WHERE gear_class = 'spur' AND id = 800",
     errors.UniqueViolation, "class spur row 800 column id: the class already has row 900 (its own)"),
    ("unknown class",
     "INSERT INTO template_view (gear_class, id, t, o) VALUES ('no_such_class', 10, 'main', '\"G90\"')",
     errors.ForeignKeyViolation,
     "class no_such_class row 10 column gear_class: gear class 'no_such_class' does not exist"),
    ("negative id",
     "UPDATE template_view SET id = -5 WHERE gear_class = 'spur' AND id = 800",
     errors.CheckViolation, "class spur row -5 column id: id must not be negative"),
    ("negative n",
     "INSERT INTO template_view (gear_class, id, t, n, o) VALUES ('spur', 851, 'main', -1, '\"G90\"')",
     errors.CheckViolation, "class spur row 851 column n: n must be a whole number >= 0, got -1"),
    ("moving a row to another class",
     "UPDATE template_view SET gear_class = 'helical' WHERE gear_class = 'spur' AND id = 800",
     errors.CheckViolation, "class spur row 800 column gear_class: a row cannot move to another class"),
    ("setting a computed column",
     "UPDATE template_view SET shared_by = 1 WHERE gear_class = 'spur' AND id = 800",
     errors.CheckViolation,
     "class spur row 800 column shared_by: shared_by and inherited_from are computed, they cannot be set"),
    ("changing an inherited row's id",
     "UPDATE template_view SET id = 310 WHERE gear_class = 'duplex' AND id = 300",
     errors.CheckViolation,
     "class duplex row 300 column id: the row is inherited from spur; its id cannot be changed in a derived class"),
    ("deleting an inherited row",
     "DELETE FROM template_view WHERE gear_class = 'duplex' AND id = 300",
     errors.RestrictViolation,
     "class duplex row 300: the row is inherited from spur; an inherited row cannot be deleted from a derived class"),
]


@pytest.mark.parametrize("statement, error, message", [case[1:] for case in REFUSALS],
                         ids=[case[0] for case in REFUSALS])
def test_the_obvious_problems_are_refused_with_a_message_and_nothing_changes(conn, statement, error, message):
    before = state(conn)
    with pytest.raises(error) as refused, conn.transaction():
        conn.execute(statement)
    assert refused.value.diag.message_primary == message
    assert state(conn) == before


def test_a_statement_with_one_bad_row_changes_no_row(conn):
    before = state(conn)
    with pytest.raises(errors.CheckViolation, match="row 1100 column p_calc"), conn.transaction():
        conn.execute("UPDATE template_view SET p_calc = CASE WHEN id = 1100 THEN 'x' END, o = o || ' + \";\"' "
                     "WHERE gear_class = 'spur' AND id IN (800, 900, 1000, 1100)")
    assert state(conn) == before



# The same rules where the engine's imports write a class (replace_class_template, issue 28: it
# checks one by one only the rows that break a rule): each bad row is refused with the words of
# template_view, the first bad row in order is the one named, and nothing changes.
GOOD_ROW = {"id": 10, "t": "main", "n": 1, "p_calc": None, "s": None, "o": '"G90"', "p_emit": None}
BAD_ROWS = [({"id": -5}, errors.CheckViolation, "class imported row -5 column id: id must not be negative"),
            ({"n": -1}, errors.CheckViolation,
             "class imported row 30 column n: n must be a whole number >= 0, got -1"),
            ({"t": "mian"}, errors.CheckViolation,
             "class imported row 30 column t: unknown module type 'mian'; use one of main, prep, sync, shift, "
             "cutcond, cutmotion"),
            ({"o": None}, errors.CheckViolation,
             "class imported row 30 column o: row has neither o nor s: it does nothing"),
            ({"p_calc": "x > 1"}, errors.CheckViolation,
             "class imported row 30 column p_calc: p_calc has no effect without s (use p_emit to decide output)")]


@pytest.mark.parametrize("change, error, message", BAD_ROWS, ids=[next(iter(case[0])) for case in BAD_ROWS])
def test_an_imported_row_breaking_a_rule_is_refused_naming_the_first_and_nothing_changes(conn, change, error, message):
    conn.execute("INSERT INTO gear_class (name) VALUES ('imported')")
    rows = [{**GOOD_ROW, "id": row_id} for row_id in (10, 20)]
    rows += [{**GOOD_ROW, "id": 30, **change}, {**GOOD_ROW, "id": 40, "n": -2}, {**GOOD_ROW, "id": 50}]
    before = state(conn)
    with pytest.raises(error) as refused, conn.transaction():
        conn.execute("SELECT replace_class_template('imported', %s)", (Jsonb(rows),))
    assert refused.value.diag.message_primary == message
    assert state(conn) == before

# --- audit ------------------------------------------------------------------------------------

def audit_rows(conn, gear_class):
    return conn.execute("SELECT changed_by, changed_at = now(), gear_class, template_version, row_id, operation, "
                        "old, new FROM template_audit WHERE gear_class = %s ORDER BY id", (gear_class,)).fetchall()


def as_json(row):
    return dict(zip(ROW_COLUMNS, row[:7]))


def test_every_change_through_the_view_is_audited_with_who_when_old_and_new(conn):
    old = as_json(view_row(conn, "spur", 800))
    seen = count(conn, "template_audit")
    with as_role(conn, "engine_editor"):
        conn.execute("UPDATE template_view SET o = '\"G90 ; AUDITED\"' WHERE gear_class = 'spur' AND id = 800")
        conn.execute("INSERT INTO template_view (gear_class, id, t, o) VALUES ('spur', 850, 'main', '\"; NEW\"')")
        conn.execute("DELETE FROM template_view WHERE gear_class = 'spur' AND id = 850")
    version = versions(conn)["spur"]
    inserted = {"id": 850, "t": "main", "n": 1, "p_calc": None, "s": None, "o": '"; NEW"', "p_emit": None}
    assert audit_rows(conn, "spur")[-3:] == [
        ("engine_editor", True, "spur", version, 800, "UPDATE", old, {**old, "o": '"G90 ; AUDITED"'}),
        ("engine_editor", True, "spur", version, 850, "INSERT", None, inserted),
        ("engine_editor", True, "spur", version, 850, "DELETE", inserted, None),
    ]
    assert count(conn, "template_audit") == seen + 3


def test_copy_on_write_of_an_inherited_row_is_audited_for_the_derived_class_only(conn):
    spur_audit = audit_rows(conn, "spur")
    conn.execute("UPDATE template_view SET n = 2 WHERE gear_class = 'duplex' AND id = 300")
    (who, _, _, _, row_id, operation, old, new), = audit_rows(conn, "duplex")[-1:]
    assert (who, row_id, operation, new["n"], old["n"]) == ("postgres", 300, "UPDATE", 2, 1)
    assert audit_rows(conn, "spur") == spur_audit


def test_engine_imports_write_one_audit_row_per_changed_row(conn):
    rows = list(load_template(conn, "helical").rows)
    seen = count(conn, "template_audit")
    edited = [TemplateRow(r.id, r.t, r.n, r.p_calc, r.s, '"G90 ; IMPORTED"', r.p_emit) if r.id == 800 else r
              for r in rows if r.id != 1100]
    assert replace_template(conn, "helical", edited)
    changes = audit_rows(conn, "helical")[-2:]
    assert [(c[4], c[5]) for c in changes] == [(800, "UPDATE"), (1100, "DELETE")]
    assert changes[0][7]["o"] == '"G90 ; IMPORTED"' and changes[1][7] is None
    assert count(conn, "template_audit") == seen + 2
    assert replace_template(conn, "helical", edited) is False       # nothing changed, nothing audited
    assert count(conn, "template_audit") == seen + 2


def test_seeding_audited_every_seeded_row(conn):
    seeded = conn.execute("SELECT count(*)::int FROM assembly").fetchone()[0]
    inserted = conn.execute("SELECT count(*)::int FROM template_audit WHERE operation = 'INSERT'").fetchone()[0]
    assert inserted == seeded


# --- the nightly refactor after SQL edits -----------------------------------------------------

@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_refactor_after_edits_merges_what_became_identical_and_nothing_else(conn):
    # through the view: spur's row 1100 made identical to helical's row 700 reuses its component
    body = view_row(conn, "helical", 700)[1:7]
    conn.execute("UPDATE template_view SET t = %s, n = %s, p_calc = %s, s = %s, o = %s, p_emit = %s "
                 "WHERE gear_class = 'spur' AND id = 1100", body)
    assert own_component(conn, "spur", 1100) == own_component(conn, "helical", 700)
    # through the component table on purpose: a spur-only body made equal to the same body
    conn.execute("UPDATE template_view SET o = '\"; SPUR ONLY\"' WHERE gear_class = 'spur' AND id = 600")
    conn.execute("UPDATE component SET t = %s, p_calc = %s, s = %s, o = %s, p_emit = %s WHERE id = %s",
                 (body[0], *body[2:], own_component(conn, "spur", 600)))
    classes = [name for (name,) in conn.execute("SELECT DISTINCT gear_class FROM template_view ORDER BY 1")]
    templates = {name: exported(conn, name) for name in classes}
    components = count(conn, "component")
    audited = count(conn, "template_audit")

    first = refactor(conn)
    assert first.changed and first.components_after == components - 1
    assert own_component(conn, "spur", 600) == own_component(conn, "helical", 700) == own_component(conn, "spur", 1100)
    assert {name: exported(conn, name) for name in classes} == templates
    assert count(conn, "template_audit") == audited                 # the refactor changes no template
    second = refactor(conn)
    assert not second.changed and second.components_after == first.components_after


# --- roles --------------------------------------------------------------------------------------

def test_the_roles_exist_and_cannot_log_in(conn):
    roles = conn.execute("SELECT rolname, rolcanlogin FROM pg_roles WHERE rolname LIKE 'engine\\_%' "
                         "ORDER BY 1").fetchall()
    assert ("engine_editor", False) in roles and ("engine_reader", False) in roles and ("engine_runner", False) in roles


FORBIDDEN = [
    ("engine_editor", "INSERT INTO program (job_id, gear_class, template_version, template_hash, name, lines, row_ids) "
                      "SELECT id, gear_class, 0, 'x', 'x', '{}', '{}' FROM job LIMIT 1"),
    ("engine_editor", "INSERT INTO job (gear_class, machine, params) SELECT 'spur', name, '{}' FROM machine LIMIT 1"),
    ("engine_editor", "UPDATE program SET name = 'x'"),
    ("engine_editor", "DELETE FROM job"),
    ("engine_editor", "DELETE FROM cutting_case"),
    ("engine_editor",
     "INSERT INTO template_audit (gear_class, row_id, operation, new) VALUES ('spur', 1, 'INSERT', '{}')"),
    ("engine_editor", "DELETE FROM template_audit"),
    ("engine_editor", "UPDATE template_audit SET changed_by = 'someone else'"),
    ("engine_runner", "UPDATE template_view SET o = '\"X\"' WHERE gear_class = 'spur' AND id = 800"),
    ("engine_runner", "INSERT INTO template_view (gear_class, id, t, o) VALUES ('spur', 851, 'main', '\"X\"')"),
    ("engine_runner", "DELETE FROM template_view WHERE gear_class = 'spur' AND id = 800"),
    ("engine_runner", "UPDATE component SET o = '\"X\"'"),
    ("engine_runner", "DELETE FROM assembly"),
    ("engine_runner", "UPDATE gear_class SET template_version = 0"),
    ("engine_runner", "DELETE FROM template_audit"),
    ("engine_reader", "INSERT INTO job (gear_class, machine, params) SELECT 'spur', name, '{}' FROM machine LIMIT 1"),
    ("engine_reader", "INSERT INTO template_view (gear_class, id, t, o) VALUES ('spur', 851, 'main', '\"X\"')"),
    ("engine_reader", "UPDATE template_view SET o = '\"X\"' WHERE gear_class = 'spur' AND id = 800"),
    ("engine_reader", "INSERT INTO component (t, o) VALUES ('main', '\"X\"')"),
    ("engine_reader", "INSERT INTO gear_class (name) VALUES ('x')"),
    ("engine_reader", "INSERT INTO cutting_case (module, teeth, material, hob_material, hob_starts, hob_tip_diameter, "
                      "cut, hob_speed, axial_feed, radial_feed) "
                      "VALUES (2, 20, 'C45', 'HSS', 1, 80, 'rough', 100, 1, 1)"),
    ("engine_reader",
     "INSERT INTO template_audit (gear_class, row_id, operation, new) VALUES ('spur', 1, 'INSERT', '{}')"),
    ("engine_reader", "SELECT audit_class_change('spur', '{}')"),
]


@pytest.mark.parametrize("role, statement", FORBIDDEN, ids=[f"{r}: {s[:40]}" for r, s in FORBIDDEN])
def test_each_role_is_refused_what_it_must_not_do(conn, role, statement):
    before = state(conn)
    with pytest.raises(errors.InsufficientPrivilege), conn.transaction(), as_role(conn, role):
        conn.execute(statement)
    assert conn.execute("SELECT current_user").fetchone()[0] == "postgres"
    assert state(conn) == before


def test_a_reader_reads_everything(conn):
    with as_role(conn, "engine_reader"):
        for table in ("template_view", "template_audit", "component", "assembly", "gear_class", "job", "program",
                      "cutting_case", "result_line", "gear", "machine", "hob"):
            conn.execute(sql.SQL("SELECT * FROM {} LIMIT 1").format(sql.Identifier(table)))
        assert load_template(conn, "spur").rows


def test_an_editor_edits_templates_a_releaser_releases_and_a_runner_instantiates_them(conn):
    with as_role(conn, "engine_editor"):
        conn.execute("UPDATE template_view SET o = '\"G90 G71 G94 ; BY EDITOR\"' "
                     "WHERE gear_class = 'spur' AND id = 800")
        conn.execute("UPDATE gear_class SET description = description || '.' WHERE name = 'spur'")
    with as_role(conn, "engine_releaser"):
        release_draft(conn, "spur")
    with as_role(conn, "engine_runner"):
        program = instantiate_gear(conn, 42)
    assert "G90 G71 G94 ; BY EDITOR" in program.lines
    assert program.template_version == versions(conn)["spur"]


def test_an_editor_may_run_the_template_import(conn):
    rows = [r if r.id != 800 else TemplateRow(r.id, r.t, r.n, r.p_calc, r.s, '"G90 ; IMPORTED"', r.p_emit)
            for r in load_template(conn, "spur").rows]
    with as_role(conn, "engine_editor"):
        assert replace_template(conn, "spur", rows)
    assert audit_rows(conn, "spur")[-1][0] == "engine_editor"


def test_roles_are_created_once_even_when_several_databases_migrate(empty_database_url):
    """Roles belong to the cluster: migrating another database finds them and carries on."""
    from engine.db.migrate import migrate

    with psycopg.connect(empty_database_url) as conn:
        assert migrate(conn)
        granted = conn.execute("SELECT has_function_privilege('engine_runner', 'store_program(bigint, text, "
                               "integer, text, text, text[], integer[], jsonb)', 'EXECUTE'), "
                               "has_table_privilege('engine_runner', 'program', 'INSERT'), "
                               "has_table_privilege('engine_editor', 'program', 'INSERT'), "
                               "has_table_privilege('engine_editor', 'template_view', 'UPDATE')").fetchone()
    assert granted == (True, False, False, True)   # programs are records: stored only through store_program


# --- concurrency --------------------------------------------------------------------------------

@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_instantiations_during_sql_edits_and_refactors_match_the_version_they_record(fresh_database_url):
    """Editors commit through the view, the refactor runs, runners instantiate, all at once:
    every program is the program of the (version, hash) it records."""
    import threading


    edits, rounds = 12, 3
    known, programs, failures = {}, [], []

    def record(conn):
        template = load_template(conn, "spur")
        known[(template.version, template.hash)] = template
        conn.commit()

    def editor():
        try:
            with psycopg.connect(fresh_database_url) as conn:
                record(conn)
                for k in range(edits):
                    conn.execute("UPDATE template_view SET o = %s WHERE gear_class = 'spur' AND id = 800",
                                 (f'"G90 G71 G94 ; EDIT {k}"',))
                    conn.commit()
                    record(conn)
        except Exception as error:  # collected and asserted below
            failures.append(error)

    def refactorer():
        try:
            with psycopg.connect(fresh_database_url) as conn:
                for _ in range(rounds):
                    refactor(conn)
        except Exception as error:
            failures.append(error)

    def runner():
        try:
            with psycopg.connect(fresh_database_url) as conn:
                for _ in range(edits):
                    program = instantiate_gear(conn, 42)
                    conn.commit()
                    programs.append(program)
        except Exception as error:
            failures.append(error)

    threads = [threading.Thread(target=target) for target in (editor, refactorer, runner, runner)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert failures == []
    with psycopg.connect(fresh_database_url) as conn:
        stored = conn.execute("SELECT id, template_version, template_hash, lines FROM program "
                              "WHERE gear_class = 'spur' ORDER BY id").fetchall()
        assert conn.execute("SELECT count(*) FROM template_audit WHERE gear_class = 'spur' AND row_id = 800 "
                            "AND operation = 'UPDATE'").fetchone()[0] == edits
    assert len(programs) == 2 * edits
    mine = {program.program_id for program in programs}
    for program_id, version, digest, lines in stored:
        if program_id not in mine:
            continue
        assert (version, digest) in known, f"program {program_id} records v{version} {digest}, never committed"
        edit_lines = [line for line in lines if line.startswith("G90 G71 G94")]
        template = known[(version, digest)]
        expected = next(row.o for row in template.rows if row.id == 800).strip('"')
        assert edit_lines == [expected]
