"""`engine plant publish` and `engine plant subscribe`: the publications and subscriptions of a head
office and its plants, made with PostgreSQL's own logical replication (docs/design.md §12). Every
refusal is one line naming what to do; nothing is made before every check passed."""
from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec
from psycopg import sql

from ..db.connection import connect, scalar, without_password
from ..errors import EngineError
from . import tables
from .tables import Published, subscription_name

if TYPE_CHECKING:
    from ..db.connection import Connection


class Subscribed(msgspec.Struct, frozen=True):
    """What `engine plant subscribe` made: the plant's number and id range, and its two subscriptions."""
    number: int
    first_id: int
    last_id: int
    templates_subscription: str
    history_subscription: str


def require_logical(conn: Connection, who: str) -> None:
    """A publisher needs wal_level = logical, which only a restart of its server sets."""
    level = scalar(conn.execute("SHOW wal_level"))
    if level != "logical":
        raise EngineError(f"{who}: the server's wal_level is {level}, a publisher needs logical: set it "
                          "(ALTER SYSTEM SET wal_level = logical) and restart the server; for the embedded "
                          "server run `engine db start --wal-level logical`")


def plant_number(conn: Connection) -> int:
    return int(scalar(conn.execute("SELECT plant_number()")))


def publish(conn: Connection) -> str:
    """The head office's publication of its released versions and their records (made, or brought
    to this engine's list of tables): its name."""
    require_logical(conn, "engine plant publish")
    number = plant_number(conn)
    if number > 0:
        raise EngineError(f"engine plant publish: this database is plant {number}; only the head office publishes "
                          "the templates (a plant publishes its history when it subscribes)")
    _publication(conn, tables.TEMPLATES_PUBLICATION, tables.HEAD_TABLES, tables.HEAD_OPERATIONS)
    conn.commit()
    return tables.TEMPLATES_PUBLICATION


def _publication(conn: Connection, name: str, published: tuple[Published, ...], operations: str) -> None:
    """CREATE PUBLICATION, or ALTER … SET TABLE for one that exists, then its operations."""
    listed = sql.SQL(", ").join(_table_spec(table) for table in published)
    exists = conn.execute("SELECT 1 FROM pg_publication WHERE pubname = %s", (name,)).fetchone()
    verb = "ALTER PUBLICATION {} SET TABLE {}" if exists else "CREATE PUBLICATION {} FOR TABLE {}"
    conn.execute(sql.SQL(verb).format(sql.Identifier(name), listed))
    conn.execute(sql.SQL("ALTER PUBLICATION {} SET (publish = {})").format(sql.Identifier(name),
                                                                          sql.Literal(operations)))


def _table_spec(table: Published) -> sql.Composable:
    spec: sql.Composable = sql.Identifier(table.table)
    if table.columns:
        spec = sql.SQL("{} ({})").format(spec, sql.SQL(", ").join(map(sql.Identifier, table.columns)))
    if table.row_filter:   # a constant of engine.plants.tables, never user input
        spec = sql.SQL("{} WHERE ({})").format(spec, sql.SQL(table.row_filter))
    return spec


def subscribe(conn: Connection, head_url: str, number: int, plant_url: str) -> Subscribed:
    """Make this database plant `number`: its id range, its history's publication, its
    subscription to the head office's templates, and the head office's subscription to its history.
    Run again on plant `number`, it makes what a failed run left unmade (each step is skipped once done)."""
    require_logical(conn, "engine plant subscribe")
    resuming = _check_plant(conn, number)
    with connect(head_url, autocommit=True) as head:
        _check_head(head, number, resuming)
        if not resuming:
            _claim_ids(conn, number)
        _publication(conn, tables.HISTORY_PUBLICATION, tables.HISTORY_TABLES, tables.HISTORY_OPERATIONS)
        conn.commit()
        conn.autocommit = True
        templates = subscription_name(number, "templates")
        _subscription(conn, templates, head_url, tables.TEMPLATES_PUBLICATION)
        history = subscription_name(number, "history")
        _subscription(head, history, plant_url, tables.HISTORY_PUBLICATION)
    return Subscribed(number, *_id_range(conn, number), templates, history)


def _check_plant(conn: Connection, number: int) -> bool:
    """A new plant: no number yet, none of the head office's rows, no row of its own outside its
    range. True: this database is plant `number` already (a run to finish, or done)."""
    here = plant_number(conn)
    if here > 0 and here != number:
        raise EngineError(f"engine plant subscribe: this database is plant {here}, not {number}; "
                          "see engine plant status")
    if here == number:
        return True
    for published in tables.HEAD_TABLES:
        if conn.execute(sql.SQL("SELECT 1 FROM {} LIMIT 1").format(sql.Identifier(published.table))).fetchone():
            raise EngineError(f"engine plant subscribe: this database holds {published.table} rows of its own; a plant "
                              "receives the head office's: subscribe a new database (engine db migrate, without "
                              "engine seed)")
    first, last = _id_range(conn, number)
    for sequence in tables.ID_SEQUENCES:
        name = sequence.removesuffix("_id_seq")
        query = sql.SQL("SELECT 1 FROM {} WHERE id NOT BETWEEN %s AND %s LIMIT 1").format(sql.Identifier(name))
        if conn.execute(query, (first, last)).fetchone():
            raise EngineError(f"engine plant subscribe: this database holds {name} rows outside plant "
                              f"{number}'s ids ({first} to {last}); they would collide at the head office: "
                              "subscribe a new database")
    return False


def _check_head(head: Connection, number: int, resuming: bool) -> None:
    """The head office has this engine's migrations (a rule only one side has would stop the
    replication), publishes, is no plant itself, and has no plant of this number yet (unless this
    database is that plant, finishing its setup)."""
    from ..db.migrate import require_current

    try:
        require_current(head)
    except EngineError as error:
        raise EngineError(f"engine plant subscribe: at the head office, {error}") from error
    _refuse_newer_head(head)
    publication = (tables.TEMPLATES_PUBLICATION,)
    if not head.execute("SELECT 1 FROM pg_publication WHERE pubname = %s", publication).fetchone():
        raise EngineError("engine plant subscribe: the head office publishes nothing yet; "
                          "run `engine plant publish` there first")
    if plant_number(head) > 0:
        raise EngineError(f"engine plant subscribe: --head names plant {plant_number(head)}, not the head office")
    if not resuming:
        _refuse_taken_number(head, number)


def _refuse_newer_head(head: Connection) -> None:
    """require_current finds a head office behind this engine, not one ahead of it (a migration of a
    newer engine): that one publishes columns or rules this plant's tables lack, and the plant's
    subscription would stop on its first copy."""
    from ..db.migrate import discover

    known = {migration.version for migration in discover()}
    newer = sorted(version for (version,) in head.execute("SELECT version FROM schema_migration")
                   if version not in known)
    if newer:
        raise EngineError(f"engine plant subscribe: the head office has migration(s) this engine lacks (first "
                          f"{newer[0]}): upgrade the engine here to the head office's and run engine db migrate")


def _refuse_taken_number(head: Connection, number: int) -> None:
    """The number is taken by a plant the head office subscribes to, or by one whose setup stopped
    before that (its templates subscription made: its slot is kept at the head office). Checked by
    the slot too: otherwise a second database took the number, then failed on the slot's name, left
    a plant that could neither finish nor take another number."""
    name = subscription_name(number, "history")
    if _subscribed(head, name):
        raise EngineError(f"engine plant subscribe: the head office has a plant {number} already ({name}); "
                          "choose another --number")
    slot = subscription_name(number, "templates")
    if head.execute("SELECT 1 FROM pg_replication_slots WHERE slot_name = %s", (slot,)).fetchone():
        raise EngineError(f"engine plant subscribe: the head office has a plant {number} already, its setup "
                          f"unfinished (slot {slot}); choose another --number, or finish that plant's setup there")


def _id_range(conn: Connection, number: int) -> tuple[int, int]:
    row = conn.execute("SELECT plant_first_id(%s), plant_last_id(%s)", (number, number)).fetchone()
    assert row is not None
    return int(row[0]), int(row[1])


def _claim_ids(conn: Connection, number: int) -> None:
    """Record the plant's number and move its id sequences into its range (bounded by it: an
    exhausted range stops with an error rather than making another plant's ids)."""
    conn.execute("INSERT INTO plant_identity (number) VALUES (%s)", (number,))
    first, last = _id_range(conn, number)
    for sequence in tables.ID_SEQUENCES:
        table = sql.Identifier(sequence.removesuffix("_id_seq"))
        start = scalar(conn.execute(sql.SQL("SELECT coalesce(max(id) + 1, %s) FROM {}").format(table), (first,)))
        conn.execute(sql.SQL("ALTER SEQUENCE {} MINVALUE {} MAXVALUE {} START WITH {} RESTART WITH {}").format(
            sql.Identifier(sequence), sql.Literal(first), sql.Literal(last), sql.Literal(first), sql.Literal(start)))


def _subscribed(conn: Connection, name: str) -> bool:
    """This database has the subscription `name`."""
    return conn.execute("SELECT 1 FROM pg_subscription WHERE subname = %s AND subdbid = (SELECT oid FROM "
                        "pg_database WHERE datname = current_database())", (name,)).fetchone() is not None


def _subscription(conn: Connection, name: str, url: str, publication: str) -> None:
    """CREATE SUBSCRIPTION unless made (its slot at the publisher takes its name); outside a transaction."""
    import psycopg

    if _subscribed(conn, name):
        return
    try:
        conn.execute(sql.SQL("CREATE SUBSCRIPTION {} CONNECTION {} PUBLICATION {}").format(
            sql.Identifier(name), sql.Literal(url), sql.Identifier(publication)))
    except psycopg.Error as error:
        first_line = without_password((str(error).strip().splitlines() or [type(error).__name__])[0], url)
        raise EngineError(f"engine plant subscribe: could not make the subscription {name} ({first_line}); "
                          "what was made before it stays: make it reachable and run the same command again") from error
