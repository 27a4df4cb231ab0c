"""Migrations: applied in order, recorded with checksums, refused when edited, serialized,
and producing exactly the readable schema in schema/."""
import re
import shutil
import threading
import uuid

import psycopg
import pytest
from psycopg import conninfo, sql

from engine.db import migrate as migrate_module
from engine.db.migrate import discover, migrate, status
from engine.errors import EngineError
from engine.paths import MIGRATIONS_DIR, SCHEMA_DIR

# The readable schema (design notes §3, Contract): the whole current schema in one file, every
# table, function, trigger and view once, in its final form, in sections by concern (each uses
# only objects of the sections before it).
SCHEMA_FILES = ("schema.sql",)
SECTIONS = ("core", "templates", "versions", "editing", "records", "programs", "release", "plants", "roles")

# Each query lists one kind of object as (key, definition) rows: the key names the object.
ACL = "(SELECT array_agg(format('%s %s', CASE WHEN a.grantee = 0 THEN 'PUBLIC' ELSE a.grantee::regrole::text END, " \
      "a.privilege_type) ORDER BY 1) FROM aclexplode({}) a)"
RELATION_ACL = """coalesce(relacl, acldefault(CASE relkind WHEN 'S' THEN 's' ELSE 'r' END::"char", relowner))"""
FUNCTION_ACL = "coalesce(proacl, acldefault('f', proowner))"   # a function's NULL acl: its owner's and PUBLIC's EXECUTE
CATALOG_QUERIES = {
    "column": """SELECT table_name || '.' || column_name, concat_ws(' ', data_type, is_nullable, column_default)
                 FROM information_schema.columns WHERE table_schema = 'public'
                 AND table_name <> 'schema_migration'""",
    "constraint": """SELECT conrelid::regclass::text || '.' || conname, pg_get_constraintdef(oid) FROM pg_constraint
                     WHERE connamespace = 'public'::regnamespace AND conrelid::regclass::text <> 'schema_migration'""",
    "index": """SELECT indexname, indexdef FROM pg_indexes WHERE schemaname = 'public'
                AND tablename <> 'schema_migration'""",
    "view": "SELECT viewname, pg_get_viewdef(viewname::regclass) FROM pg_views WHERE schemaname = 'public'",
    "function": """SELECT oid::regprocedure::text, pg_get_functiondef(oid) FROM pg_proc
                   WHERE pronamespace = 'public'::regnamespace""",
    "trigger": """SELECT tgrelid::regclass::text || '.' || tgname, pg_get_triggerdef(oid) || ' ' || tgenabled::text
                  FROM pg_trigger WHERE NOT tgisinternal""",
    "role": "SELECT rolname, rolcanlogin::text FROM pg_roles WHERE rolname LIKE 'engine\\_%'",
    "module type": "SELECT code, position::text FROM module_type",
    "privileges on": f"""SELECT relname, {ACL.format(RELATION_ACL)}::text
                         FROM pg_class WHERE relnamespace = 'public'::regnamespace
                         AND relkind IN ('r', 'v', 'S') AND relname <> 'schema_migration'""",
    "column privileges on": f"""SELECT attrelid::regclass::text || '.' || attname, {ACL.format("attacl")}::text
                                FROM pg_attribute WHERE attacl IS NOT NULL
                                AND attrelid::regclass::text NOT LIKE 'pg\\_%'""",
    "execute privileges on": f"""SELECT oid::regprocedure::text, {ACL.format(FUNCTION_ACL)}::text
                                 FROM pg_proc WHERE pronamespace = 'public'::regnamespace""",
    "schema privileges on": f"SELECT nspname, {ACL.format('nspacl')}::text FROM pg_namespace WHERE nspname = 'public'",
    "default privileges of": f"""SELECT defaclrole::regrole::text || ' ' || defaclobjtype::text,
                                        {ACL.format('defaclacl')}::text
                                 FROM pg_default_acl WHERE defaclnamespace = 'public'::regnamespace""",
}


def catalog(url) -> dict[str, dict[str, str]]:
    """Every object of the database by kind: {kind: {object: its definition}}."""
    with psycopg.connect(url) as conn:
        return {kind: dict(conn.execute(query).fetchall()) for kind, query in CATALOG_QUERIES.items()}


def load_schema(url) -> None:
    with psycopg.connect(url) as conn:
        for name in SCHEMA_FILES:
            conn.execute((SCHEMA_DIR / name).read_text(encoding="utf-8"))
        conn.commit()


def differences(from_schema, from_migrations) -> list[str]:
    """One line per object that schema/ and migrations/ do not define alike."""
    found = []
    for kind, objects in from_migrations.items():
        theirs = from_schema[kind]
        found += [f"{kind} {key}: only the migrations make it" for key in sorted(objects.keys() - theirs.keys())]
        found += [f"{kind} {key}: only schema/ makes it" for key in sorted(theirs.keys() - objects.keys())]
        found += [f"{kind} {key} differs" for key in sorted(objects.keys() & theirs.keys())
                  if objects[key] != theirs[key]]
    return found


def test_schema_folder_is_one_readable_file_in_its_sections():
    assert sorted(path.name for path in SCHEMA_DIR.glob("*.sql")) == sorted(SCHEMA_FILES)
    text = (SCHEMA_DIR / "schema.sql").read_text(encoding="utf-8")
    banners = [line.removeprefix("-- Section ").partition(":")[0] for line in text.splitlines()
               if line.startswith("-- Section ")]
    assert banners == list(SECTIONS)


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
def test_migrations_produce_exactly_the_readable_schema(empty_database_url, database_url):
    load_schema(empty_database_url)
    assert differences(catalog(empty_database_url), catalog(database_url)) == []


def test_a_difference_from_the_migrations_is_named_by_its_object(empty_database_url, database_url):
    load_schema(empty_database_url)
    with psycopg.connect(empty_database_url) as conn:
        conn.execute("CREATE OR REPLACE FUNCTION class_depth_limit() RETURNS integer LANGUAGE sql IMMUTABLE "
                     "PARALLEL SAFE RETURN 40")
        conn.execute("ALTER TABLE hob DROP CONSTRAINT hob_safe_id")
        conn.commit()
    assert differences(catalog(empty_database_url), catalog(database_url)) == [
        "constraint hob.hob_safe_id: only the migrations make it", "function class_depth_limit() differs"]


# A definition in schema/: what it makes (function, view, trigger, table, index) and its identity.
DEFINITION = re.compile(r"\bCREATE\s+(?:OR\s+REPLACE\s+)?(?:UNIQUE\s+)?(?:CONSTRAINT\s+)?"
                        r"(FUNCTION|VIEW|TRIGGER|TABLE|INDEX)\s+(\w+)", re.IGNORECASE)
TRIGGER_TABLE = re.compile(r"\bON\s+(\w+)", re.IGNORECASE)


def argument_types(text: str, start: int) -> str:
    """The types of a function's parameters whose list opens at text[start]: an overload is another function."""
    depth, end = 0, start
    for end in range(start, len(text)):
        depth += {"(": 1, ")": -1}.get(text[end], 0)
        if depth == 0:
            break
    types = []
    for parameter in re.split(r",(?![^(]*\))", text[start + 1:end]):
        words = re.split(r"\s+DEFAULT\s+|\s*=\s*", parameter.strip(), flags=re.IGNORECASE)[0].split()
        types.append(" ".join(words[1:] if len(words) > 1 else words))
    return ", ".join(t for t in types if t)


def definitions(text: str) -> list[str]:
    """Every object the SQL text creates, named so that two definitions of one object read alike."""
    text = re.sub(r"--[^\n]*", "", text)
    named = []
    for match in DEFINITION.finditer(text):
        kind, name = match.group(1).lower(), match.group(2)
        if kind == "function":
            name += f"({argument_types(text, match.end() + text[match.end():].index('('))})"
        elif kind == "trigger":
            name += " on " + TRIGGER_TABLE.search(text, match.end()).group(1)
        named.append(f"{kind} {name}")
    return named


def defined_twice(text: str) -> list[str]:
    named = definitions(text)
    return sorted({name for name in named if named.count(name) > 1})


def schema_text() -> str:
    return "\n".join((SCHEMA_DIR / name).read_text(encoding="utf-8") for name in SCHEMA_FILES)


def test_schema_folder_defines_each_object_once():
    assert defined_twice(schema_text()) == []
    assert "OR REPLACE" not in schema_text().upper()   # a later definition would silently win


def test_a_second_definition_in_the_schema_folder_is_found():
    second = ("CREATE OR REPLACE FUNCTION check_program() RETURNS trigger LANGUAGE plpgsql AS $$ BEGIN RETURN NEW; "
              "END $$;\nCREATE TRIGGER check_program BEFORE INSERT ON program FOR EACH ROW EXECUTE FUNCTION x();\n"
              "CREATE OR REPLACE VIEW result_line AS SELECT 1;\n")
    assert defined_twice(schema_text() + second) == [
        "function check_program()", "trigger check_program on program", "view result_line"]


def test_overloads_and_like_named_triggers_are_not_second_definitions():
    text = ("CREATE FUNCTION f(a integer) RETURNS int RETURN 1;\nCREATE FUNCTION f(a integer, b text DEFAULT 'x') "
            "RETURNS int RETURN 2;\nCREATE TRIGGER t BEFORE INSERT ON one FOR EACH ROW EXECUTE FUNCTION g();\n"
            "CREATE TRIGGER t BEFORE INSERT ON two FOR EACH ROW EXECUTE FUNCTION g();\n")
    assert definitions(text) == ["function f(integer)", "function f(integer, text)", "trigger t on one",
                                 "trigger t on two"]
    assert defined_twice(text + "CREATE FUNCTION f(b integer) RETURNS int RETURN 3;") == ["function f(integer)"]


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


@pytest.mark.slow   # two migrations with 1.6 s of pauses each; 5-30 s beside the other worker's tests
def test_two_databases_migrating_at_once_on_a_fresh_server_both_get_the_roles(
        server_url, database_pool, _empty_databases, tmp_path, monkeypatch):
    """Roles are the cluster's: on a fresh server (every embedded one, a new CI machine) two
    databases migrating at once raced to create them, and the loser of 0015 failed with 'role
    "engine_releaser" does not exist' (its failed lookup stays cached for the transaction).
    Migrations 0001-0015 with roles of their own (a fresh server's absent roles, without
    touching the server's real ones), run on two databases at once, with pauses in 0005 and
    0015 that make the race happen every time: between "no such role yet" and CREATE ROLE
    (both see it missing), and after the block (the first one's creation stays uncommitted
    meanwhile). Without the pauses it failed 4 runs in 6 on this machine."""
    suffix = uuid.uuid4().hex[:6]
    roles = {role: f"{role}_{suffix}" for role in migrate_module.CLUSTER_ROLES}
    folder = tmp_path / "migrations"
    folder.mkdir()
    for migration in discover()[:15]:   # up to 0015, the last that creates a role
        text = migration.text
        for role, renamed in roles.items():
            text = re.sub(rf"\b{role}\b", renamed, text)
        (folder / migration.path.name).write_text(with_pauses(text))
    monkeypatch.setattr(migrate_module, "CLUSTER_ROLES", tuple(roles.values()))
    # two empty databases of the pool (issue 28: made ahead, dropped behind, where CREATE and DROP
    # DATABASE here cost seconds of checkpoints on a shared server)
    urls = [conninfo.make_conninfo(server_url, dbname=database_pool.take(_empty_databases)) for _ in range(2)]
    try:
        assert migrate_at_once(urls, folder) == []
    finally:
        drop_roles_of(server_url, urls, list(roles.values()))
        for url in urls:
            database_pool.give_back(conninfo.conninfo_to_dict(url)["dbname"])


ROLE_CHECK = re.compile(r"(IF NOT EXISTS \(SELECT 1 FROM pg_roles WHERE rolname = [^)]*\) THEN)")
BLOCK_END = re.compile(r"^END\s*\$\$;$", re.MULTILINE)


def drop_roles_of(server_url: str, urls: list[str], roles: list[str]) -> None:
    """Drop the test's roles while the databases they own objects in are still there (the pool
    drops those later): their objects and grants in each database first (DROP OWNED)."""
    with psycopg.connect(server_url, autocommit=True) as admin:
        made = [name for (name,) in admin.execute("SELECT rolname FROM pg_roles WHERE rolname = ANY(%s)", (roles,))]
    if not made:
        return
    names = sql.SQL(", ").join(map(sql.Identifier, made))
    for url in urls:
        with psycopg.connect(url, autocommit=True) as conn:
            conn.execute(sql.SQL("DROP OWNED BY {}").format(names))
    with psycopg.connect(server_url, autocommit=True) as admin:
        admin.execute(sql.SQL("DROP ROLE {}").format(names))


def with_pauses(text: str) -> str:
    """A migration that creates roles, paused 0.2 s before each CREATE ROLE and 0.6 s after its
    block (in the same transaction); any other as it is."""
    if not ROLE_CHECK.search(text):
        return text
    text = ROLE_CHECK.sub(r"\1 PERFORM pg_sleep(0.2);", text)
    block = BLOCK_END.search(text, text.index("CREATE ROLE"))
    assert block is not None, "the role's DO block ends with END $$;"
    return text[:block.end()] + "\nSELECT pg_sleep(0.6);" + text[block.end():]


def migrate_at_once(urls, folder) -> list[Exception]:
    errors: list[Exception] = []

    def run(url):
        try:
            with psycopg.connect(url) as conn:
                migrate(conn, folder)
        except Exception as error:  # collected and returned
            errors.append(error)

    threads = [threading.Thread(target=run, args=(url,)) for url in urls]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    return errors


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


@pytest.mark.slow   # issue 28: among the fast subset's slowest; the whole suite runs it
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
