"""Template versions (issue 6): every committed version of a class is stored; history, diff
and restore, in the library and on the command line."""
import shutil

import psycopg
import pytest
from msgspec.structs import asdict
from psycopg import sql

from engine.db.migrate import migrate
from engine.errors import EngineError
from engine.paths import MIGRATIONS_DIR
from engine.templates.history import diff, history, restore
from engine.templates.store import load_template
from engine.templates.template_csv import export_csv


def exported(conn, gear_class):
    return export_csv(load_template(conn, gear_class))


def current_version(conn, gear_class):
    return conn.execute("SELECT template_version FROM gear_class WHERE name = %s", (gear_class,)).fetchone()[0]


def a_plain_row(conn, gear_class):
    """The first row of the class with an o and no s (safe to give another o)."""
    return conn.execute("SELECT id, o FROM template_view WHERE gear_class = %s AND o IS NOT NULL AND s IS NULL "
                        "ORDER BY id LIMIT 1", (gear_class,)).fetchone()


def edit_as(url, role, gear_class, row_id, o):
    """One committed UPDATE of template_view, acting as `role`."""
    with psycopg.connect(url) as conn:
        conn.execute(sql.SQL("SET ROLE {}").format(sql.Identifier(role)))
        updated = conn.execute("UPDATE template_view SET o = %s WHERE gear_class = %s AND id = %s",
                               (o, gear_class, row_id)).rowcount
        assert updated == 1


@pytest.fixture
def edited(fresh_database_url):
    """spur edited twice through template_view by engine_editor: (url, row id, old o, versions)."""
    url = fresh_database_url
    with psycopg.connect(url) as conn:
        row_id, old_o = a_plain_row(conn, "spur")
        first = current_version(conn, "spur")
    edit_as(url, "engine_editor", "spur", row_id, '"G90 ; FIRST EDIT"')
    edit_as(url, "engine_editor", "spur", row_id, '"G90 ; SECOND EDIT"')
    return url, row_id, old_o, (first, first + 1, first + 2)


def test_every_seeded_class_has_its_current_version_stored(conn):
    """Compared with the template as the engine loads it, not with the SQL that stored it."""
    stored = dict(conn.execute("SELECT v.gear_class, v.rows FROM template_version_rows v JOIN gear_class g "
                               "ON g.name = v.gear_class AND g.template_version = v.version").fetchall())
    with_rows = [name for (name,) in conn.execute(
        "SELECT name FROM gear_class g WHERE EXISTS (SELECT 1 FROM class_template(g.name))")]
    assert {"spur", "helical", "duplex", "turning_iso"} <= set(with_rows)
    for name in with_rows:
        assert stored.get(name) == [asdict(row) for row in load_template(conn, name).rows], name


def test_the_migration_stores_the_current_version_of_classes_loaded_before_it(empty_database_url, tmp_path):
    """Templates written by an engine of migration 0005 (plain rows, a version the old engine
    counted): migrating stores each class's current version, with the hash programs record."""
    folder = tmp_path / "migrations"
    folder.mkdir()
    for path in sorted(MIGRATIONS_DIR.glob("*.sql"))[:5]:
        shutil.copy(path, folder)
    with psycopg.connect(empty_database_url) as conn:
        migrate(conn, folder)
        conn.execute("INSERT INTO gear_class (name, template_version) VALUES ('old_unit', 3)")
        conn.execute("INSERT INTO gear_class (name, parent, template_version) VALUES ('old_pair', 'old_unit', 2)")
        for gear_class, row_id, o in (("old_unit", 10, '"G90"'), ("old_unit", 20, '"M30"'),
                                      ("old_pair", 15, '"; PAIR ÄÖ \\t"')):
            conn.execute("WITH c AS (INSERT INTO component (t, o) VALUES ('main', %s) RETURNING id) "
                         "INSERT INTO assembly (gear_class, id, component_id) SELECT %s, %s, id FROM c",
                         (o, gear_class, row_id))
        conn.commit()
        migrate(conn)
        conn.commit()
        stored = dict(conn.execute("SELECT v.gear_class, v.hash FROM template_version_rows v JOIN gear_class g "
                                   "ON g.name = v.gear_class AND g.template_version = v.version").fetchall())
        loaded = {name: load_template(conn, name) for name in ("old_unit", "old_pair")}
    assert stored == {name: template.hash for name, template in loaded.items()}
    assert [template.version for template in loaded.values()] == [3, 2]


def test_history_lists_each_version_with_who_and_the_row_changed(edited):
    url, row_id, _, (first, second, third) = edited
    with psycopg.connect(url) as conn:
        entries = {entry.version: entry for entry in history(conn, "spur")}
    assert {first, second, third} <= entries.keys()
    assert entries[second].created_by == entries[third].created_by == "engine_editor"
    assert entries[second].changes == entries[third].changes == ((row_id, "UPDATE"),)
    assert entries[third].rows == entries[first].rows


def test_diff_shows_exactly_the_changed_row_old_and_new_o(edited):
    url, row_id, old_o, (first, _, third) = edited
    with psycopg.connect(url) as conn:
        changes = diff(conn, "spur", first, third)
    assert [(c.row_id, c.kind, c.columns) for c in changes] == [(row_id, "changed", ["o"])]
    assert (changes[0].old["o"], changes[0].new["o"]) == (old_o, '"G90 ; SECOND EDIT"')


def test_restore_brings_back_the_earlier_export_as_a_new_version(fresh_database_url):
    url = fresh_database_url
    with psycopg.connect(url) as conn:
        row_id, _ = a_plain_row(conn, "spur")
        before, first = exported(conn, "spur"), current_version(conn, "spur")
    edit_as(url, "engine_editor", "spur", row_id, '"G90 ; EDITED"')
    with psycopg.connect(url) as conn:
        assert exported(conn, "spur") != before
        changed, now = restore(conn, "spur", first)
        conn.commit()
        assert changed and now == first + 2
        assert exported(conn, "spur") == before
        assert [e.version for e in history(conn, "spur")][-3:] == [first, first + 1, first + 2]


def test_restore_of_a_derived_class_makes_an_overridden_row_inherited_again(fresh_database_url):
    url = fresh_database_url
    with psycopg.connect(url) as conn:
        row_id, _ = a_plain_row(conn, "duplex")
        assert conn.execute("SELECT inherited_from FROM template_view WHERE gear_class = 'duplex' AND id = %s",
                            (row_id,)).fetchone()[0] != "duplex"
        before, first = exported(conn, "duplex"), current_version(conn, "duplex")
    edit_as(url, "engine_editor", "duplex", row_id, '"G90 ; DUPLEX ONLY"')
    with psycopg.connect(url) as conn:
        restore(conn, "duplex", first)
        conn.commit()
        assert exported(conn, "duplex") == before
        own = conn.execute("SELECT 1 FROM assembly WHERE gear_class = 'duplex' AND id = %s", (row_id,)).fetchone()
        assert own is None


def test_an_unknown_version_is_refused_naming_the_stored_ones_and_nothing_changes(conn):
    before, version = exported(conn, "spur"), current_version(conn, "spur")
    with pytest.raises(EngineError, match=rf"class 'spur' has no version 999; stored versions: .*\b{version}\b"):
        restore(conn, "spur", 999)
    assert (exported(conn, "spur"), current_version(conn, "spur")) == (before, version)
    with pytest.raises(EngineError, match="has no version 998"):
        diff(conn, "spur", version, 998)
    with pytest.raises(EngineError, match="'no_such' does not exist"):
        history(conn, "no_such")


# --- command line ---------------------------------------------------------------------------

def test_cli_history_diff_restore(run):
    with psycopg.connect(run.url) as conn:
        row_id, old_o = a_plain_row(conn, "spur")
        before, first = exported(conn, "spur"), current_version(conn, "spur")
    edit_as(run.url, "engine_editor", "spur", row_id, '"G90 ; CLI EDIT"')

    shown = run("template", "history", "--class", "spur")
    assert shown.exit_code == 0, shown.output
    assert f"v{first + 1}" in shown.stdout and "engine_editor" in shown.stdout and f"UPDATE {row_id}" in shown.stdout

    changed = run("template", "diff", "--class", "spur", "--from", first, "--to", first + 1)
    assert changed.exit_code == 0, changed.output
    new_o = '"G90 ; CLI EDIT"'
    assert changed.stdout == f"~ {row_id} o: {old_o!r} -> {new_o!r}\n"

    restored = run("template", "restore", "--class", "spur", "--version", first)
    assert restored.exit_code == 0, restored.output
    assert f"restored version {first} as version {first + 2}" in restored.stdout
    with psycopg.connect(run.url) as conn:
        assert exported(conn, "spur") == before


def test_cli_json_and_one_line_errors(read_only_run):
    shown = read_only_run("template", "history", "--class", "spur", "--json")
    assert shown.exit_code == 0 and '"versions"' in shown.stdout
    refused = read_only_run("template", "restore", "--class", "spur", "--version", 999)
    assert refused.exit_code == 1
    assert refused.stderr.count("\n") == 1 and "has no version 999; stored versions:" in refused.stderr


@pytest.mark.parametrize("command, words", [
    ("history", ["--class", "--json", "version"]),
    ("diff", ["--from", "--to", "--json", "added"]),
    ("restore", ["--version", "new version"]),
])
def test_help_texts(read_only_run, command, words):
    result = read_only_run("template", command, "--help")
    assert result.exit_code == 0
    assert all(word in result.stdout for word in words), result.stdout
