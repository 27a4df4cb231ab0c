"""Migrations: applied in order, recorded with checksums, refused when edited, serialized,
and producing exactly the readable schema in schema/."""
import shutil
import threading

import psycopg
import pytest

from engine.db.migrate import discover, migrate, status
from engine.errors import EngineError
from engine.paths import MIGRATIONS_DIR, SCHEMA_DIR

CATALOG_QUERIES = {
    "columns": """SELECT table_name, column_name, data_type, is_nullable, column_default
                  FROM information_schema.columns WHERE table_schema = 'public'
                  AND table_name <> 'schema_migration' ORDER BY 1, 2""",
    "constraints": """SELECT conrelid::regclass::text, conname, pg_get_constraintdef(oid) FROM pg_constraint
                      WHERE connamespace = 'public'::regnamespace
                      AND conrelid::regclass::text <> 'schema_migration' ORDER BY 1, 2""",
    "indexes": """SELECT indexname, indexdef FROM pg_indexes WHERE schemaname = 'public'
                  AND tablename <> 'schema_migration' ORDER BY 1""",
    "views": "SELECT viewname, pg_get_viewdef(viewname::regclass) FROM pg_views WHERE schemaname = 'public' ORDER BY 1",
    "functions": """SELECT proname, pg_get_functiondef(oid) FROM pg_proc
                    WHERE pronamespace = 'public'::regnamespace ORDER BY 1, 2""",
    "triggers": """SELECT tgrelid::regclass::text, tgname, pg_get_triggerdef(oid) FROM pg_trigger
                   WHERE NOT tgisinternal ORDER BY 1, 2""",
    "roles": "SELECT rolname, rolcanlogin FROM pg_roles WHERE rolname LIKE 'engine\\_%' ORDER BY 1",
    "module types": "SELECT code, position FROM module_type ORDER BY position",
}


def catalog(url):
    with psycopg.connect(url) as conn:
        return {name: conn.execute(query).fetchall() for name, query in CATALOG_QUERIES.items()}


def test_migrations_produce_exactly_the_readable_schema(empty_database_url, database_url):
    with psycopg.connect(empty_database_url) as conn:
        conn.execute((SCHEMA_DIR / "schema.sql").read_text())
        conn.commit()
    from_schema, from_migrations = catalog(empty_database_url), catalog(database_url)
    for part in CATALOG_QUERIES:
        assert from_schema[part] == from_migrations[part], f"schema/schema.sql differs in {part}"


def test_status_lists_every_migration_as_applied(database_url):
    with psycopg.connect(database_url) as conn:
        states = status(conn)
    assert [s.migration.path.name for s in states] == [m.path.name for m in discover()]
    assert {s.state for s in states} == {"applied"}


def test_second_migrate_applies_nothing(fresh_database_url):
    with psycopg.connect(fresh_database_url) as conn:
        assert migrate(conn) == []


def copy_migrations(tmp_path):
    folder = tmp_path / "migrations"
    shutil.copytree(MIGRATIONS_DIR, folder)
    return folder


def test_an_edited_applied_migration_is_refused(fresh_database_url, tmp_path):
    folder = copy_migrations(tmp_path)
    first = sorted(folder.glob("*.sql"))[0]
    first.write_text(first.read_text() + "\n-- edited after it ran\n")
    with psycopg.connect(fresh_database_url) as conn:
        with pytest.raises(EngineError, match="edited since it ran"):
            migrate(conn, folder)
        assert [s.state for s in status(conn, folder)][0] == "CHANGED"


def test_a_failing_migration_rolls_back_and_says_which(fresh_database_url, tmp_path):
    folder = copy_migrations(tmp_path)
    (folder / "9001.good_then_bad.sql").write_text(
        "CREATE TABLE half_done (x int);\nSELECT no_such_function();\n")
    with psycopg.connect(fresh_database_url) as conn:
        with pytest.raises(EngineError, match="9001.good_then_bad.sql failed"):
            migrate(conn, folder)
        assert conn.execute("SELECT to_regclass('half_done')").fetchone()[0] is None
        assert [s.state for s in status(conn, folder)][-1] == "pending"


def test_a_badly_named_migration_file_is_an_error(tmp_path):
    folder = copy_migrations(tmp_path)
    (folder / "add_things.sql").write_text("SELECT 1;")
    with pytest.raises(EngineError, match="NNNN.slug.sql"):
        discover(folder)


def test_concurrent_migrate_runs_apply_each_migration_once(empty_database_url):
    errors, applied = [], []

    def run():
        try:
            with psycopg.connect(empty_database_url) as conn:
                applied.extend(m.version for m in migrate(conn))
        except Exception as error:  # collected and asserted below
            errors.append(error)

    threads = [threading.Thread(target=run) for _ in range(3)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert errors == []
    assert sorted(applied) == sorted(m.version for m in discover())


def test_hob_ids_differing_only_in_case_stop_migration_0011_with_their_names(empty_database_url, tmp_path):
    folder = copy_migrations(tmp_path)
    later = [path for path in folder.glob("*.sql") if path.name >= "0011"]
    held = {path.name: path.read_text() for path in later}
    for path in later:
        path.unlink()
    hob = ("INSERT INTO hob (id, module, starts, tip_diameter, length, hand, accuracy_class) "
           "VALUES (%s, 2, 1, 70, 100, 'R', 'AA')")
    with psycopg.connect(empty_database_url) as conn:
        migrate(conn, folder)
        for hob_id in ("H-M2-AA-R1", "h-m2-aa-r1", "H-OTHER"):
            conn.execute(hob, (hob_id,))
        conn.commit()
        for name, text in held.items():
            (folder / name).write_text(text)
        with pytest.raises(EngineError, match=r'0011\.hob_ids_ignore_case\.sql failed.*"H-M2-AA-R1" and "h-m2-aa-r1"'):
            migrate(conn, folder)
        assert conn.execute("SELECT count(*) FROM hob").fetchone()[0] == 3


def test_versions_stored_before_0025_keep_the_layout_their_programs_were_written_with(empty_database_url, tmp_path):
    """Before migration 0025 every program of a class was written with the class's one layout:
    the versions already stored record it, so programs of them are shown as they were written."""
    from engine.nc.layout import CRLF, NcLayout, class_layout
    from engine.templates.rows import TemplateRow
    from engine.templates.store import ensure_class, replace_template

    folder = copy_migrations(tmp_path)
    later = [path for path in folder.glob("*.sql") if path.name >= "0025"]
    held = {path.name: path.read_text() for path in later}
    for path in later:
        path.unlink()
    with psycopg.connect(empty_database_url) as conn:
        migrate(conn, folder)
        ensure_class(conn, "old_crlf")
        replace_template(conn, "old_crlf", [TemplateRow(10, "main", 10, None, None, '"M30"', None)])
        conn.execute("UPDATE gear_class SET line_ending = %s, final_newline = false WHERE name = 'old_crlf'", (CRLF,))
        conn.commit()
        for name, text in held.items():
            (folder / name).write_text(text)
        migrate(conn, folder)
        assert class_layout(conn, "old_crlf", 1) == NcLayout(CRLF, False)
        assert conn.execute("SELECT template_version FROM gear_class WHERE name = 'old_crlf'").fetchone()[0] == 1
