"""`engine db backup FILE` and `engine db restore FILE` (issue 31): a round trip into an empty
database gives back every table's rows, on whichever server the suite runs (the embedded
PostgreSQL 18 with the package's own pg_dump, or ENGINE_TEST_DSN's with the one on PATH); the
refusals change nothing; a dump tool of another version is refused naming both versions."""
from __future__ import annotations

import stat
from pathlib import Path

import psycopg
import pytest
from psycopg import sql

from engine.db import backup as backups
from engine.db.dump_tools import DumpTools, dump_tools
from engine.errors import EngineError

TABLES = """SELECT c.relname FROM pg_class c JOIN pg_namespace n ON n.oid = c.relnamespace
            WHERE n.nspname = 'public' AND c.relkind IN ('r', 'p') ORDER BY 1"""
SEQUENCES = "SELECT sequencename, last_value FROM pg_sequences WHERE schemaname = 'public' ORDER BY 1"


def contents(url: str) -> dict:
    """Every public table's rows as text, sorted, and every sequence's last value."""
    with psycopg.connect(url) as conn:
        tables = [name for (name,) in conn.execute(TABLES)]
        rows = {name: sorted(row[0] for row in conn.execute(
            sql.SQL("SELECT t::text FROM {} t").format(sql.Identifier(name)))) for name in tables}
        return {"rows": rows, "sequences": conn.execute(SEQUENCES).fetchall()}


def one_line_refusal(result) -> str:
    assert result.exit_code == 1 and result.stderr.count("\n") == 1, (result.exit_code, result.output)
    assert "Traceback" not in result.output
    return result.stderr


@pytest.fixture
def stored(run):
    """The seeded copy with a stored program (gear 42's) in it."""
    made = run("instantiate", "--gear", 42)
    assert made.exit_code == 0, made.output
    return run


def test_backup_restored_into_an_empty_database_gives_every_row_back(stored, empty_database_url, tmp_path):
    file = tmp_path / "engine.dump"
    made = stored("db", "backup", file)
    assert made.exit_code == 0, made.output
    assert file.stat().st_size > 0 and [path.name for path in tmp_path.iterdir()] == ["engine.dump"]
    restored = stored("db", "restore", file, url=False, env={"DATABASE_URL": empty_database_url})
    assert restored.exit_code == 0, restored.output
    assert "its migrations match this installation's" in restored.stdout
    before, after = contents(stored.url), contents(empty_database_url)
    assert after["rows"]["program"] and after["rows"]["gear"]   # a stored program and the seeded data came along
    assert after == before


def test_restore_into_a_database_that_is_not_empty_is_refused_and_changes_nothing(stored, tmp_path):
    file = tmp_path / "engine.dump"
    assert stored("db", "backup", file).exit_code == 0
    before = contents(stored.url)
    message = one_line_refusal(stored("db", "restore", file))
    assert "is not empty" in message and "nothing changed" in message
    assert contents(stored.url) == before


def test_a_backup_of_edited_migrations_is_refused_before_restoring(run, empty_database_url, tmp_path):
    with psycopg.connect(run.url) as conn:
        conn.execute("UPDATE schema_migration SET checksum = 'edited' WHERE version = '0001'")
    file = tmp_path / "engine.dump"
    assert run("db", "backup", file).exit_code == 0
    message = one_line_refusal(run("db", "restore", file, url=False, env={"DATABASE_URL": empty_database_url}))
    assert "0001." in message and "nothing restored" in message
    assert contents(empty_database_url) == {"rows": {}, "sequences": []}


def test_an_existing_backup_file_is_kept_unless_forced(read_only_run, tmp_path):
    file = tmp_path / "engine.dump"
    file.write_bytes(b"yesterday's backup")
    message = one_line_refusal(read_only_run("db", "backup", file))
    assert "exists" in message and "--force" in message
    assert file.read_bytes() == b"yesterday's backup"
    assert read_only_run("db", "backup", file, "--force").exit_code == 0
    assert file.read_bytes().startswith(b"PGDMP")   # the custom format's magic
    assert [path.name for path in tmp_path.iterdir()] == ["engine.dump"]


def test_a_backup_into_a_missing_folder_is_refused(read_only_run, tmp_path):
    message = one_line_refusal(read_only_run("db", "backup", tmp_path / "typo" / "engine.dump"))
    assert "does not exist" in message and not (tmp_path / "typo").exists()


def fake_tool(folder: Path, name: str, version: str, body: str = "") -> Path:
    """A script that says it is `name` of PostgreSQL `version` (and runs `body` otherwise)."""
    folder.mkdir(exist_ok=True)
    tool = folder / name
    tool.write_text(f'#!/bin/sh\nif [ "$1" = --version ]; then echo "{name} (PostgreSQL) {version}"; exit 0; fi\n'
                    f"{body}\n")
    tool.chmod(tool.stat().st_mode | stat.S_IEXEC)
    return tool


def test_dump_tools_of_another_major_version_are_refused_naming_both(tmp_path):
    old = tmp_path / "15"
    for name in ("pg_dump", "pg_restore"):
        fake_tool(old, name, "15.20 (Debian 15.20-0+deb12u1)")
    with pytest.raises(EngineError) as refused:
        dump_tools("18", [old, tmp_path / "absent"])
    message = str(refused.value)
    assert "PostgreSQL 18" in message and f"{old / 'pg_dump'} is 15" in message and "\n" not in message


def test_dump_tools_are_taken_from_the_first_folder_of_the_servers_version(tmp_path):
    for folder, version in (("15", "15.20"), ("18", "18.1")):
        for name in ("pg_dump", "pg_restore"):
            fake_tool(tmp_path / folder, name, version)
    chosen = dump_tools("18", [tmp_path / "15", tmp_path / "18"])
    assert chosen == DumpTools(str(tmp_path / "18" / "pg_dump"), str(tmp_path / "18" / "pg_restore"), "18")


def test_a_failed_dump_leaves_no_file(database_url, tmp_path, monkeypatch):
    half = fake_tool(tmp_path / "bin", "pg_dump", "18.1", 'while [ "$1" != --file ]; do shift; done; '
                     'echo half > "$2"; echo "pg_dump: error: disk full" >&2; exit 1')
    monkeypatch.setattr(backups, "tools_for", lambda conn: DumpTools(str(half), "pg_restore", "18"))
    folder = tmp_path / "out"
    folder.mkdir()
    with pytest.raises(EngineError, match="pg_dump failed: pg_dump: error: disk full; nothing written"):
        backups.backup(database_url, folder / "engine.dump")
    assert list(folder.iterdir()) == []
