"""`engine db backup FILE` and `engine db restore FILE`: the whole database in pg_dump's custom
format (-Fc: compressed, read back by pg_restore), with the dump tools of the server's version
(engine.db.dump_tools).

A backup is never half a file: pg_dump writes a temporary file beside FILE, which takes FILE's name
only when pg_dump succeeded (an existing FILE is replaced only with --force). A restore goes only
into an empty database, in one transaction (a failure leaves it empty), and only a backup whose
migrations are this installation's, unchanged (design notes §3: an applied migration is never
edited): the archive's schema_migration ledger is read and checked before anything is restored,
and the restored database's migration status checked after."""
from __future__ import annotations

import os
import subprocess
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import msgspec

from ..errors import EngineError
from .connection import connect
from .dump_tools import DumpTools, tools_for
from .migrate import create_cluster_roles, discover, status

if TYPE_CHECKING:
    from .connection import Connection

# The first object of a database that is not empty: a relation or routine outside the system's
# schemas, or a schema of its own (a new database has only `public`).
FIRST_OBJECT = """
SELECT kind || ' ' || name FROM (
    SELECT 'relation' AS kind, n.nspname || '.' || c.relname AS name, n.nspname
      FROM pg_class c JOIN pg_namespace n ON n.oid = c.relnamespace
    UNION ALL
    SELECT 'routine', n.nspname || '.' || p.proname, n.nspname
      FROM pg_proc p JOIN pg_namespace n ON n.oid = p.pronamespace
    UNION ALL
    SELECT 'schema', n.nspname, n.nspname FROM pg_namespace n WHERE n.nspname <> 'public'
) objects
WHERE nspname NOT IN ('pg_catalog', 'information_schema') AND nspname NOT LIKE 'pg\\_toast%'
  AND nspname NOT LIKE 'pg\\_temp\\_%'
ORDER BY 1 LIMIT 1"""
LEDGER = "schema_migration"


class Done(msgspec.Struct, frozen=True):
    """What a backup wrote or a restore read, for the command's one line."""
    file: Path
    database: str
    tools: DumpTools
    size: int               # bytes of the backup file
    pending: int = 0        # after a restore: migrations of this installation the backup lacks


def backup(url: str, file: Path, force: bool = False) -> Done:
    """Dump the database of `url` into `file` (custom format); `force` replaces an existing file."""
    _check_target(file, force)
    with connect(url, autocommit=True) as conn:
        tools, database = tools_for(conn), conn.info.dbname
    part = _temporary_beside(file)
    try:
        _run([tools.pg_dump, "--format=custom", "--file", str(part), *_dbname(url)], "pg_dump", "nothing written")
        _put_in_place(part, file, force)
    finally:
        part.unlink(missing_ok=True)
    return Done(file, database, tools, file.stat().st_size)


def _check_target(file: Path, force: bool) -> None:
    if not file.parent.is_dir():
        raise EngineError(f"backup: the folder {file.parent} does not exist; create it first or name another")
    if file.is_dir():
        raise EngineError(f"backup: {file} is a folder; name a file in it")
    if file.exists() and not force:
        raise EngineError(f"backup: {file} exists; name another file, or give --force to replace it")


def _temporary_beside(file: Path) -> Path:
    """An empty hidden file in FILE's folder for pg_dump to write (renamed onto FILE when whole)."""
    try:
        handle, name = tempfile.mkstemp(prefix=f".{file.name}.", suffix=".part", dir=file.parent)
    except OSError as error:
        raise EngineError(f"backup: cannot write in {file.parent} ({error.strerror or error}); "
                          "name a folder you can write") from None
    os.close(handle)
    return Path(name)


def _put_in_place(part: Path, file: Path, force: bool) -> None:
    """The finished dump takes the file's name in one step: replacing it with `force`, else only
    if no file of that name appeared meanwhile (a hard link fails on an existing name)."""
    if force:
        return os.replace(part, file)
    try:
        os.link(part, file)
    except FileExistsError as error:
        raise EngineError(f"backup: {file} appeared while dumping; nothing written; run again") from error
    except OSError:   # a file system without hard links
        if file.exists():
            raise EngineError(f"backup: {file} appeared while dumping; nothing written; run again") from None
        os.replace(part, file)


def _dbname(url: str) -> list[str]:
    """The connection for a dump tool: the URL, or none (libpq's PG* variables) when it is empty."""
    return ["--dbname", url] if url else []


def _run(command: list[str], tool: str, outcome: str) -> str:
    """Run a dump tool; its failure is refused in one line with the line of its stderr saying why."""
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        lines = [line.strip() for line in done.stderr.splitlines() if line.strip()]
        reason = next((line for line in lines if "error:" in line), lines[-1] if lines else f"exit {done.returncode}")
        raise EngineError(f"{tool} failed: {reason}; {outcome}")
    return done.stdout


def restore(url: str, file: Path) -> Done:
    """Restore `file` into the empty database of `url`, then check its migrations are this installation's."""
    if not file.is_file():
        raise EngineError(f"restore: no backup file {file}; name the file `engine db backup` wrote")
    with connect(url, autocommit=True) as conn:
        tools, database = tools_for(conn), conn.info.dbname
        _require_empty(conn, database)
        _check_ledger(archived_ledger(tools, file), file)
        create_cluster_roles(conn)   # the roles the backup's grants name (cluster-wide, not in a dump)
    _run([tools.pg_restore, "--single-transaction", "--exit-on-error", "--no-owner", *_dbname(url), str(file)],
         "pg_restore", f"the database {database} is left empty")
    with connect(url, autocommit=True) as conn:
        return Done(file, database, tools, file.stat().st_size, _restored_pending(conn, database))


def _require_empty(conn: Connection, database: str) -> None:
    row = conn.execute(FIRST_OBJECT).fetchone()
    if row is not None:
        raise EngineError(f"restore: the database {database} is not empty (it has the {row[0]}); nothing changed; "
                          "restore into a new database (CREATE DATABASE …) named by --database-url")


def archived_ledger(tools: DumpTools, file: Path) -> dict[str, str]:
    """version → checksum of the backup's schema_migration rows, read from the archive (nothing restored)."""
    text = _run([tools.pg_restore, "--data-only", "--table", LEDGER, "--file", "-", str(file)],
                "pg_restore", "nothing restored (is it a backup `engine db backup` wrote?)")
    lines = text.splitlines()
    start = next((i for i, line in enumerate(lines) if line.startswith("COPY ") and f".{LEDGER} (" in line), None)
    if start is None:
        raise EngineError(f"restore: {file} holds no migration ledger ({LEDGER}): not a backup of an engine "
                          "database; nothing restored")
    columns = [name.strip() for name in lines[start].split("(", 1)[1].split(")", 1)[0].split(",")]
    rows = [dict(zip(columns, line.split("\t"))) for line in lines[start + 1:lines.index("\\.", start)]]
    return {row["version"]: row["checksum"] for row in rows}


def _check_ledger(ledger: dict[str, str], file: Path) -> None:
    """Every migration the backup applied is one of this installation's, with the same checksum."""
    known = {migration.version: migration for migration in discover()}
    for version in sorted(ledger):
        migration = known.get(version)
        if migration is None:
            raise EngineError(f"restore: {file} was made by a newer engine (migration {version} is not in this "
                              "installation); nothing restored; upgrade the engine first")
        if migration.checksum != ledger[version]:
            raise EngineError(f"restore: {file} applied migration {migration.path.name} with another checksum than "
                              "this installation's file; nothing restored; restore with the engine version that "
                              "made it")


def _restored_pending(conn: Connection, database: str) -> int:
    """The restored database's migrations checked against the files: none changed; how many pending."""
    states = status(conn)
    changed = [state.migration.path.name for state in states if state.changed]
    if changed:
        raise EngineError(f"restore: the database {database} was restored but its migration {changed[0]} differs "
                          "from this installation's; run the engine version that made the backup")
    return sum(state.applied_at is None for state in states)
