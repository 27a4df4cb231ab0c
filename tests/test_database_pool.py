"""The test database pool (tests/helpers/database_pool.py) drops every database it made: those given
back while the session runs, and at close the rest, through the detached dropper. A dropper that
fails (it runs with its output thrown away) left a thousand 10 MB databases on the local server
in three sessions before anyone saw it (issue 28)."""
from __future__ import annotations

import time

import psycopg
from helpers.database_pool import DatabasePool, create_database, drop_later

PATIENCE = 120.0   # seconds: on a shared server each DROP DATABASE waits for a checkpoint


def existing(server_url: str, names: list[str]) -> set[str]:
    with psycopg.connect(server_url, autocommit=True) as admin:
        rows = admin.execute("SELECT datname FROM pg_database WHERE datname = ANY(%s)", (names,)).fetchall()
    return {name for (name,) in rows}


def gone(server_url: str, names: list[str]) -> bool:
    """Whether none of `names` exists, waiting up to PATIENCE for the background drops."""
    deadline = time.monotonic() + PATIENCE
    while existing(server_url, names) and time.monotonic() < deadline:
        time.sleep(0.1)
    return not existing(server_url, names)


def test_the_detached_dropper_drops_every_database_it_is_given(server_url):
    names = ["engine_dropper_test_a", "engine_dropper_test_b"]
    with psycopg.connect(server_url, autocommit=True) as admin:
        for name in names:
            create_database(admin, name)
    assert existing(server_url, names) == set(names)
    drop_later(server_url, names)
    assert gone(server_url, names)


def test_the_pool_drops_what_is_given_back_and_at_close_what_it_made_ahead(server_url):
    pool = DatabasePool(server_url)
    empty = pool.kind(None, "engine_pool_test", ahead=2)
    used = pool.take(empty)
    pool.give_back(used)
    assert gone(server_url, [used])
    deadline = time.monotonic() + PATIENCE
    while len(empty.ready) < empty.ahead and time.monotonic() < deadline:
        time.sleep(0.1)
    ahead = list(empty.ready)
    assert len(ahead) == 2 and existing(server_url, ahead) == set(ahead)
    pool.close()
    assert gone(server_url, ahead)
