"""The nightly refactor (design notes §5) on a library a gear shop really has: every real NC
program of tests/data (plasmac imperial/metric pairs, lathe macros, CAM and EMCO
programs) imported next to the seeded gear classes. Checked: the refactor is lossless
(every class's export byte-identical, every imported class still instantiates to its
file's bytes), merges the copies a DBA's SQL edits leave (each body stored once
afterwards), is idempotent; the lines shared by a family's members are one component;
and instantiation running during a refactor sees the old library, never a mix, while
writers wait for the refactor."""
from __future__ import annotations

import threading

import psycopg
import pytest
from helpers.lineage_text import id_masked
from helpers.nc_files import DATA, FAMILY, PARAMS, class_name, instantiate, real_files
from helpers.refactor import bodies_stored_twice, component_count, duplicate_row_body, exports
from msgspec.structs import replace

from engine.library.nc_import import import_nc
from engine.library.refactor import STAGES, refactor
from engine.nc.layout import class_layout, nc_text
from engine.programs.instantiate import instantiate_gear
from engine.templates.evaluator import evaluate
from engine.templates.expressions import compile_expression
from engine.templates.store import load_template, replace_template

SEEDED_CLASSES = {"spur", "helical", "taper", "crowned", "worm_wheel", "duplex"}
WAIT = 30   # seconds: no wait of this file blocks longer, so a bug fails instead of hanging


@pytest.fixture
def imported_library(real_library):
    """(URL, class name → file) of the worker's copy of the seeded database with every real NC
    program imported and committed (tests/conftest.py real_library: each file imported once per
    worker, shared with the import tests of other files), for the tests of this module that
    refactor it, each of which gets a connection rolled back at its end (library_conn)."""
    imported = {}
    for relative in real_files():   # in this order: of two files with one class name, the last is the class
        real_library.imported(relative)
        imported[class_name(relative)] = relative
    return real_library.url, imported


@pytest.fixture
def library_conn(imported_library):
    """A connection to the imported library whose every change is rolled back at the end of the test."""
    with psycopg.connect(imported_library[0]) as connection:
        with connection.transaction(force_rollback=True):
            yield connection


def rows_sharing_a_body(conn, first_class: str, second_class: str) -> list[tuple[int, int]]:
    """(row id in first_class, row id in second_class) pairs whose rows use one component."""
    return conn.execute("SELECT a.id, b.id FROM assembly a JOIN assembly b ON b.component_id = a.component_id "
                        "WHERE a.gear_class = %s AND b.gear_class = %s ORDER BY a.id, b.id",
                        (first_class, second_class)).fetchall()


def first_parameterised_row(conn, gear_class: str) -> int:
    """The class's first f-string row (its first row if it has none)."""
    return conn.execute("SELECT a.id FROM assembly a JOIN component c ON c.id = a.component_id "
                        "WHERE a.gear_class = %s ORDER BY (c.o LIKE 'f%%') DESC, a.id LIMIT 1",
                        (gear_class,)).fetchone()[0]


def assembly_mapping(conn) -> dict[tuple[str, int], int]:
    """(gear_class, row id) → component_id of the whole assembly table, in one statement."""
    return {(name, row_id): component for name, row_id, component
            in conn.execute("SELECT gear_class, id, component_id FROM assembly")}


@pytest.mark.slow   # refactors every real program with the seeded classes (the import: imported_library)
def test_real_programs_and_seeded_classes_refactor_losslessly_and_idempotently(library_conn, imported_library):
    conn, imported = library_conn, imported_library[1]
    before = exports(conn)
    assert SEEDED_CLASSES | set(imported) <= set(before)

    first = refactor(conn)
    assert exports(conn) == before
    assert bodies_stored_twice(conn) == 0
    second = refactor(conn)
    assert second.changed is False
    assert second.components_before == second.components_after == first.components_after == component_count(conn)
    assert exports(conn) == before
    for name, relative in imported.items():
        lines = instantiate(conn, name, PARAMS[relative]).split("\n")[:-1]   # written with the class's layout:
        text = nc_text(lines, class_layout(conn, name))                       # a CR LF file comes back CR LF
        assert text.encode() == (DATA / relative).read_bytes(), name


@pytest.mark.slow   # refactors every real program with the seeded classes (the import: imported_library)
def test_copies_left_by_sql_edits_are_merged_across_real_and_seeded_classes(library_conn):
    conn = library_conn
    imperial, metric = class_name(FAMILY + "imperial_ramp_pierce.ngc"), class_name(FAMILY + "metric_ramp_pierce.ngc")
    shared = rows_sharing_a_body(conn, imperial, metric)
    assert shared, "the ramp_pierce pair shares no line: nothing to test the family body on"
    imperial_row, metric_row = shared[0]
    rows = [(imperial, imperial_row), (metric, metric_row), ("spur", 1400)] + [
        (name, first_parameterised_row(conn, name)) for name in
        (class_name("linuxcnc/lathe_macros/turning.ngc"), class_name("linuxcnc/lathe_macros/threading.ngc"),
         class_name("sinumerik/cam_840dsl/CAM_TEST.MPF"), class_name("emco_from_dxf/testNegDXF.cnc"))]
    originals = {row: duplicate_row_body(conn, *row) for row in rows}
    copies = len(rows)
    assert bodies_stored_twice(conn) == len({original for original, _ in originals.values()})
    count, before = component_count(conn), exports(conn)

    report = refactor(conn)

    assert report.changed is True
    assert (report.components_before, report.components_after) == (count, count - copies)
    assert component_count(conn) == count - copies
    assert bodies_stored_twice(conn) == 0
    assert exports(conn) == before
    mapping = assembly_mapping(conn)
    assert all(mapping[row] == original for row, (original, _) in originals.items())
    assert mapping[(imperial, imperial_row)] == mapping[(metric, metric_row)]
    again = refactor(conn)
    assert again.changed is False and again.components_after == count - copies


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_lines_the_wrench_pair_shares_are_stored_once(conn):
    files = {unit: FAMILY + f"{unit}_wrench.ngc" for unit in ("imperial", "metric")}
    lines = {unit: (DATA / relative).read_text().split("\n")[:-1] for unit, relative in files.items()}
    in_both = set(lines["imperial"]) & set(lines["metric"])
    real_shared = {"M3 $0 S1 (start plasma torch)", "M5 $0 (stop plasma torch)", "M2 (end program)",
                   "#<holes> = 4 (holes and arcs with overburn)"}
    assert real_shared <= in_both   # what the files contain: these lines are in both programs
    assert "G20 (imperial units)" not in in_both
    assert "G64 P0.005 (path tolerance)" in lines["imperial"] and "G64 P0.125 (path tolerance)" in lines["metric"]
    for relative in files.values():
        import_nc(conn, DATA / relative, class_name(relative), PARAMS[relative])
    imperial, metric = (class_name(relative) for relative in files.values())

    bodies = conn.execute("""
        SELECT c.o, count(DISTINCT c.id)::int, array_agg(DISTINCT c.id)
        FROM assembly a JOIN component c ON c.id = a.component_id
        WHERE a.gear_class IN (%s, %s)
        GROUP BY c.t, c.o, c.p_calc, c.s, c.p_emit
        HAVING count(DISTINCT a.gear_class) = 2""", (imperial, metric)).fetchall()
    assert bodies
    assert all(copies == 1 for _, copies, _ in bodies)
    produced = {unit: {evaluate(compile_expression(o), dict(PARAMS[relative]))
                       for o, _, _ in bodies} for unit, relative in files.items()}
    for unit in files:
        assert real_shared <= produced[unit] <= set(lines[unit])
    # one parameterised body gives each member its own path tolerance line
    assert "G64 P0.005 (path tolerance)" in produced["imperial"]
    assert "G64 P0.125 (path tolerance)" in produced["metric"]
    ids = [ids[0] for _, _, ids in bodies]
    shared_by = conn.execute("SELECT v.shared_by FROM template_view v JOIN assembly a "
                             "ON (a.gear_class, a.id) = (v.gear_class, v.id) "
                             "WHERE a.gear_class IN (%s, %s) AND a.component_id = ANY(%s)",
                             (imperial, metric, ids)).fetchall()
    assert len(shared_by) >= 2 * len(ids)
    assert all(count >= 2 for (count,) in shared_by)


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_instantiation_during_a_refactor_sees_the_old_library_and_writers_wait(fresh_database_url):
    url = fresh_database_url
    with psycopg.connect(url) as setup:
        assert bodies_stored_twice(setup) == 0
        spur_rows = [row_id for (row_id,) in setup.execute(
            "SELECT id FROM assembly WHERE gear_class = 'spur' AND id % 200 = 0 ORDER BY id")]
        rows = [("spur", row_id) for row_id in spur_rows] + [("helical", 1400), ("worm_wheel", 1410)]
        original_of = {copy: original for original, copy in (duplicate_row_body(setup, *row) for row in rows)}
    assert len(original_of) == len(rows) >= 5

    reader = psycopg.connect(url)
    writer = psycopg.connect(url)
    reached, release, outcome = threading.Event(), threading.Event(), {}

    def hold_before_commit(stage, done, total):
        if stage == STAGES[-1] == "check invariants":
            reached.set()
            if not release.wait(WAIT):
                raise TimeoutError("the test never released the refactor")

    def run_refactor():
        try:
            with psycopg.connect(url) as refactoring:
                outcome["report"] = refactor(refactoring, progress=hold_before_commit)
        except BaseException as error:   # noqa: BLE001 — handed to the main thread
            outcome["error"] = error
            reached.set()

    try:
        for connection, timeout in ((reader, "2s"), (writer, "1s")):
            connection.execute(f"SET lock_timeout = '{timeout}'")
            connection.commit()
        old_library = assembly_mapping(reader)
        assert set(original_of) <= set(old_library.values())
        lines_before = id_masked(instantiate_gear(reader, 42).lines)
        reader.commit()
        # taper has no copied row: only the refactor's table lock, not a row lock, can hold it up
        taper = load_template(writer, "taper").rows
        writer.rollback()

        thread = threading.Thread(target=run_refactor, daemon=True)
        thread.start()
        try:
            assert reached.wait(WAIT), "the refactor never reached its last stage"
            assert "error" not in outcome, outcome.get("error")
            assert assembly_mapping(reader) == old_library
            assert id_masked(instantiate_gear(reader, 42).lines) == lines_before
            reader.commit()
            edited = [replace(row, o='";$PATH=/_N_WKS_DIR"') if row.id == 200 else row for row in taper]
            assert edited != list(taper)
            with pytest.raises(psycopg.errors.LockNotAvailable):
                replace_template(writer, "taper", edited)
            writer.rollback()
        finally:
            release.set()
            thread.join(WAIT)
        assert not thread.is_alive()
        assert "error" not in outcome, outcome.get("error")
        assert outcome["report"].changed is True
        assert outcome["report"].components_after == outcome["report"].components_before - len(rows)

        new_library = assembly_mapping(reader)
        assert new_library == {key: original_of.get(component, component)
                               for key, component in old_library.items()}
        assert not set(original_of) & set(new_library.values())
        assert bodies_stored_twice(reader) == 0
        assert id_masked(instantiate_gear(reader, 42).lines) == lines_before
        reader.commit()
    finally:
        release.set()
        reader.close()
        writer.close()


@pytest.mark.slow   # seconds: out of the fast subset (make test-fast), in every full run
def test_a_refactor_that_deadlocks_with_a_hand_made_sql_edit_retries_and_commits(fresh_database_url):
    """A DBA's edit that changes assembly first and component second, while the refactor
    waits for its lock on both: PostgreSQL aborts one of them; the refactor runs again."""
    url = fresh_database_url
    with psycopg.connect(url) as setup:
        duplicate_row_body(setup, "spur", 1400)
    editor = psycopg.connect(url)
    editor.execute("SET deadlock_timeout = '30s'")
    editor.commit()
    outcome = {}

    def run_refactor():
        try:
            with psycopg.connect(url) as refactoring:
                outcome["report"] = refactor(refactoring)
        except BaseException as error:   # noqa: BLE001 — handed to the main thread
            outcome["error"] = error

    thread = threading.Thread(target=run_refactor, daemon=True)
    try:
        editor.execute("DELETE FROM assembly WHERE gear_class = 'taper' AND id = 200")
        thread.start()
        waiting = "SELECT count(*) FROM pg_locks WHERE NOT granted AND relation = 'assembly'::regclass"
        with psycopg.connect(url, autocommit=True) as watcher:
            for _ in range(WAIT * 10):
                if watcher.execute(waiting).fetchone()[0]:
                    break
                threading.Event().wait(0.1)
            else:
                pytest.fail("the refactor never waited for the editor's lock")
        # The editor waits longer before looking for deadlocks, so PostgreSQL aborts the
        # refactor (which must retry), not the editor.
        editor.execute("INSERT INTO component (t, o) VALUES ('main', '\"; EDITED BY HAND\"')")
        editor.rollback()
        thread.join(WAIT)
        assert not thread.is_alive()
        assert "error" not in outcome, outcome.get("error")
        assert outcome["report"].changed is True
        with psycopg.connect(url) as check:
            assert bodies_stored_twice(check) == 0
    finally:
        editor.close()
