"""Plain-SQL migrations `NNNN.slug.sql`, applied in order, each in its own transaction,
recorded with a checksum, serialized by an advisory lock (the yoyo/alembic way)."""
from __future__ import annotations

import hashlib
import re
from pathlib import Path
from typing import TYPE_CHECKING

import msgspec
from psycopg import sql

from ..errors import EngineError
from ..paths import MIGRATIONS_DIR
from .connection import scalar

if TYPE_CHECKING:
    from .connection import Connection

MIGRATION_FILE = re.compile(r"^(\d{4})\.([a-z0-9_-]+)\.sql$")
# Any constant works: all engines on one database agree on it.
MIGRATION_LOCK_KEY = 0x4E43_5445_4D50  # "NCTEMP"

# The roles the migrations grant to (0005, 0015). Roles are cluster-wide: two databases migrating at
# once on a fresh server race to create them, and the loser's CREATE ROLE waits for the winner,
# fails as a duplicate, and its next GRANT in the same transaction still finds no role (PostgreSQL
# keeps the failed lookup cached until the transaction ends). Created first, each committed on its
# own, the migrations' own "IF NOT EXISTS" then finds them.
CLUSTER_ROLES = ("engine_reader", "engine_runner", "engine_editor", "engine_releaser", "engine_planner")
ROLE_EXISTS = "SELECT 1 FROM pg_roles WHERE rolname = %s"

CREATE_LEDGER = """
CREATE TABLE IF NOT EXISTS schema_migration (
    version    text PRIMARY KEY,
    name       text NOT NULL,
    checksum   text NOT NULL,
    applied_at timestamptz NOT NULL DEFAULT now()
)"""


class Migration(msgspec.Struct, frozen=True):
    """A migration file NNNN.slug.sql of this installation."""
    version: str
    name: str
    path: Path

    @property
    def text(self) -> str:
        return self.path.read_text(encoding="utf-8")

    @property
    def checksum(self) -> str:
        return hashlib.sha256(self.path.read_bytes()).hexdigest()


class MigrationState(msgspec.Struct, frozen=True):
    """A migration and whether (and when) the database applied it, and whether its file changed since."""
    migration: Migration
    applied_at: object | None  # datetime when applied
    changed: bool              # applied, but the file differs from what was applied

    @property
    def state(self) -> str:
        if self.applied_at is None:
            return "pending"
        return "CHANGED" if self.changed else "applied"


def discover(directory: Path | None = None) -> list[Migration]:
    """The migration files in version order (of this installation's migrations/ by default); a
    stray .sql file is an error, not a skip. None at all is an installation without its data
    (a wheel built without them): refused, or `db migrate` would report success on nothing."""
    directory = directory or MIGRATIONS_DIR
    migrations = []
    for path in sorted(directory.glob("*.sql")):
        match = MIGRATION_FILE.match(path.name)
        if not match:
            raise EngineError(f"migration file {path.name} is not named NNNN.slug.sql; rename it")
        migrations.append(Migration(match.group(1), match.group(2), path))
    versions = [m.version for m in migrations]
    if len(versions) != len(set(versions)):
        raise EngineError(f"two migration files in {directory} share a version number")
    if not migrations:
        raise EngineError(f"no migrations found in {directory}: this installation is incomplete; "
                          "reinstall the engine (pip install .) or run it from a checkout")
    return migrations


def status(conn: Connection, directory: Path | None = None) -> list[MigrationState]:
    applied = _applied(conn)
    states = []
    for migration in discover(directory):
        record = applied.get(migration.version)
        states.append(MigrationState(
            migration,
            record[1] if record is not None else None,
            record is not None and record[0] != migration.checksum,
        ))
    return states


def migrate(conn: Connection, directory: Path | None = None) -> list[Migration]:
    """Apply every pending migration; return those applied. Refuses if an applied file changed.
    Each migration commits on its own, so the connection must not be inside a transaction."""
    from psycopg.pq import TransactionStatus

    discover(directory)   # an installation without migrations is refused before anything is written
    if conn.info.transaction_status != TransactionStatus.IDLE:
        conn.commit()  # our own reads so far (status queries); migrations need real transactions
    autocommit, conn.autocommit = conn.autocommit, True
    conn.execute("SELECT pg_advisory_lock(%s)", (MIGRATION_LOCK_KEY,))
    try:
        conn.execute(CREATE_LEDGER)  # under the lock: IF NOT EXISTS alone is not race-free
        return _apply_pending(conn, directory)
    finally:
        conn.execute("SELECT pg_advisory_unlock(%s)", (MIGRATION_LOCK_KEY,))
        conn.autocommit = autocommit


def _apply_pending(conn: Connection, directory: Path | None) -> list[Migration]:
    states = status(conn, directory)
    changed = [s.migration.path.name for s in states if s.changed]
    if changed:
        raise EngineError(
            f"applied migration {changed[0]} was edited since it ran (checksum differs); "
            "restore the file and put the change in a new migration"
        )
    done: list[Migration] = []
    if any(state.applied_at is None for state in states):
        create_cluster_roles(conn)
    for state in states:
        if state.applied_at is None:
            _apply(conn, state.migration)
            done.append(state.migration)
    return done


def create_cluster_roles(conn: Connection) -> None:
    """Each missing role of CLUSTER_ROLES created and committed alone (the connection is in
    autocommit); one created meanwhile by another database's migration is left as it is."""
    import psycopg

    for role in CLUSTER_ROLES:
        if conn.execute(ROLE_EXISTS, (role,)).fetchone() is not None:
            continue
        try:
            conn.execute(sql.SQL("CREATE ROLE {} NOLOGIN").format(sql.Identifier(role)))
        except (psycopg.errors.DuplicateObject, psycopg.errors.UniqueViolation):
            pass   # created meanwhile: the other database's commit is what we waited for


def _apply(conn: Connection, migration: Migration) -> None:
    import psycopg

    try:
        with conn.transaction():
            conn.execute(sql.SQL(migration.text))
            conn.execute(
                "INSERT INTO schema_migration (version, name, checksum) VALUES (%s, %s, %s)",
                (migration.version, migration.name, migration.checksum),
            )
    except psycopg.Error as error:
        raise EngineError(
            f"migration {migration.path.name} failed and was rolled back: "
            f"{str(error).strip().splitlines()[0]}"
        ) from error


def _applied(conn: Connection) -> dict[str, tuple[str, object]]:
    exists = scalar(conn.execute("SELECT to_regclass('schema_migration') IS NOT NULL"))
    if not exists:
        return {}
    rows = conn.execute("SELECT version, checksum, applied_at FROM schema_migration").fetchall()
    return {version: (checksum, applied_at) for version, checksum, applied_at in rows}


def require_current(conn: Connection) -> None:
    """Refuse to work on a database whose schema is behind the code."""
    pending = [s.migration.path.name for s in status(conn) if s.state != "applied"]
    if pending:
        raise EngineError(
            f"the database schema is not current ({len(pending)} migration(s) pending or changed, "
            f"first {pending[0]}); run `engine db migrate`"
        )
