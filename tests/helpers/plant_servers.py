"""The two servers of the plants tests (issue 33; tests/test_plants.py, test_plants_screens.py,
test_adversary33_plants.py): a head office and plant 7, each an embedded PostgreSQL with wal_level =
logical, set up through the engine's commands, and the helpers the tests share. Every wait is for a
state PostgreSQL reports, bounded so a broken setup fails instead of hanging."""
from __future__ import annotations

import json
import shutil
import tempfile
import time
import uuid
from pathlib import Path

import msgspec
import psycopg
import pytest
from click.testing import CliRunner
from psycopg import sql

from engine.cli.app import main

SEED = Path(__file__).resolve().parent.parent.parent / "seed_templates"
PLANT = 7
FIRST_ID, LAST_ID = PLANT * 10**10, (PLANT + 1) * 10**10 - 1   # docs/design.md §12: number·10^10 on
LOOPBACK = "http://127.0.0.1"   # the open web view answers a loopback Host only
WAIT_SECONDS = 180   # a bound for a broken setup, never an assertion on speed
TEMPLATES_SLOT, HISTORY_SLOT = f"engine_plant_{PLANT}_templates", f"engine_plant_{PLANT}_history"


class Server(msgspec.Struct):
    data_dir: Path
    url: str = ""


def engine(server: Server, *args, url: str | None = None):
    """The CLI in-process on `server` (its data directory for the engine db commands, its URL for the rest)."""
    given = ["--database-url", url] if url else []
    env = {"ENGINE_DATA_DIR": str(server.data_dir), "ENGINE_CONFIG": "", "DATABASE_URL": None, "PGHOST": None,
           "PGPORT": None, "PGDATABASE": None}
    return CliRunner().invoke(main, [*given, *map(str, args)], env=env)


def ok(result) -> str:
    assert result.exit_code == 0, result.output
    return result.stdout


def start(server: Server) -> str:
    """Start the server with wal_level = logical: the URL of its database `engine`."""
    return ok(engine(server, "db", "start", "--wal-level", "logical")).strip()


def new_database(server_url: str, prefix: str) -> str:
    """A database of a unique name on the server, and its URL."""
    name = f"{prefix}_{uuid.uuid4().hex[:10]}"
    with psycopg.connect(server_url, autocommit=True) as conn:
        conn.execute(sql.SQL("CREATE DATABASE {}").format(sql.Identifier(name)))
    return server_url.replace("/engine?", f"/{name}?", 1)


def rows(url: str, query: str, params=()) -> list[tuple]:
    with psycopg.connect(url, autocommit=True) as conn:
        return conn.execute(query, params).fetchall()


def wait_until(check, what: str):
    deadline = time.monotonic() + WAIT_SECONDS
    while time.monotonic() < deadline:
        found = check()
        if found:
            return found
        time.sleep(0.2)
    raise AssertionError(f"not within {WAIT_SECONDS} s: {what}")


def caught_up(publisher_url: str, slot: str) -> None:
    """Wait until the subscriber of `slot` has confirmed everything committed at the publisher so far."""
    lsn = rows(publisher_url, "SELECT pg_current_wal_lsn()")[0][0]
    wait_until(lambda: rows(publisher_url, "SELECT confirmed_flush_lsn >= %s FROM pg_replication_slots "
                                           "WHERE slot_name = %s", (lsn, slot)) == [(True,)],
               f"slot {slot} confirms {lsn}")


def tables_ready(url: str) -> bool:
    states = rows(url, "SELECT srsubstate FROM pg_subscription_rel")
    return bool(states) and all(state == "r" for (state,) in states)


class Group(msgspec.Struct):
    head: Server
    plant: Server
    head_url: str
    plant_url: str


@pytest.fixture(scope="module")
def group():   # the tests that take it are slow: two servers of their own
    folder = Path(tempfile.mkdtemp(prefix="plants-", dir="/tmp"))   # short: the servers' sockets live there
    head, plant = Server(folder / "head"), Server(folder / "plant")
    try:
        head.url, plant.url = start(head), start(plant)
        made = Group(head, plant, new_database(head.url, "head"), new_database(plant.url, "plant"))
        for args in (("db", "migrate"), ("seed",), ("hobs", "import", SEED / "hobs.csv"),
                     ("gears", "import", SEED / "gears.csv"), ("plant", "publish")):
            ok(engine(head, *args, url=made.head_url))
        ok(engine(plant, "db", "migrate", url=made.plant_url))
        ok(engine(plant, "plant", "subscribe", "--head", made.head_url, "--number", PLANT, url=made.plant_url))
        wait_until(lambda: tables_ready(made.plant_url), "the plant has copied the head office's tables")
        wait_until(lambda: tables_ready(made.head_url), "the head office has copied the plant's history")
        ok(engine(plant, "gears", "import", SEED / "gears.csv", url=made.plant_url))   # the plant's own gears
        yield made
    finally:
        _clean_up(head, plant, folder)


def _clean_up(head: Server, plant: Server, folder: Path) -> None:
    """Drop the subscriptions (each drops its slot at its publisher, so both servers run), then stop
    the servers whatever happened, and check that no slot was left to hold WAL."""
    left: list[tuple] = []
    try:
        for server in (head, plant):
            if server.url:
                start(server)
        for server in (plant, head):
            if server.url:
                _drop_subscriptions(server)
        left = [row for server in (head, plant) if server.url
                for row in rows(server.url, "SELECT slot_name FROM pg_replication_slots")]
    finally:
        for server in (head, plant):
            if server.url:
                engine(server, "db", "stop")
        shutil.rmtree(folder, ignore_errors=True)
    assert left == []


def _drop_subscriptions(server: Server) -> None:
    for (database,) in rows(server.url, "SELECT datname FROM pg_database WHERE datname ~ '^(head|plant)_'"):
        url = server.url.replace("/engine?", f"/{database}?", 1)
        with psycopg.connect(url, autocommit=True) as conn:
            for (name,) in conn.execute("SELECT subname FROM pg_subscription WHERE subdbid = "
                                        "(SELECT oid FROM pg_database WHERE datname = current_database())").fetchall():
                conn.execute(sql.SQL("DROP SUBSCRIPTION {}").format(sql.Identifier(name)))


def released(url: str, gear_class: str) -> tuple[int, str]:
    return rows(url, "SELECT version, hash FROM template_release WHERE gear_class = %s ORDER BY id DESC LIMIT 1",
                (gear_class,))[0]


def versions(url: str, gear_class: str) -> set[int]:
    return {version for (version,) in rows(url, "SELECT version FROM template_version_rows WHERE gear_class = %s",
                                           (gear_class,))}


def edit_spur(url: str, text: str) -> int:
    """A draft of class spur at the head office (SQL editing through template_view): its version."""
    with psycopg.connect(url) as conn:
        conn.execute("DELETE FROM template_view WHERE gear_class = 'spur' AND id = 350")
        conn.execute("INSERT INTO template_view (gear_class, id, t, n, o, p_emit) "
                     "VALUES ('spur', 350, 'main', 1, %s, 'dialect == ''840d''')", (f'"; {text}"',))
    return rows(url, "SELECT template_version FROM gear_class WHERE name = 'spur'")[0][0]


def instantiate(server: Server, url: str) -> dict:
    return json.loads(ok(engine(server, "instantiate", "--gear", 42, "--json", url=url)))


def program_lines(url: str, program_id: int) -> list[str]:
    return rows(url, "SELECT lines FROM program WHERE id = %s", (program_id,))[0][0]
