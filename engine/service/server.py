"""Running the service (`engine serve`): the web view served by uvicorn on one socket, bound to
loopback unless asked otherwise (any other address asks for a login first), until Ctrl-C or
`engine serve stop`. The running service is known by its pid file in the engine's runtime folder
(engine.paths.runtime_folder), held under an exclusive lock for the life of the process: a lock
dies with its process, so a file left by a crash (or a pid the system gave to another program
since) is never taken for a running service, and `stop` never signals a stranger.

What runs is a list of parts (ServeOptions): the web view always; program delivery by FTP
(`--ftp-port`) and request folders (`--requests ROOT`) beside it when asked for, each started
before the web view says its address and closed when it ends (engine.service.ftp,
engine.service.request_folder)."""
from __future__ import annotations

import contextlib
import fcntl
import os
import secrets
import signal
import socket
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO

import msgspec

from ..errors import EngineError
from ..paths import runtime_folder
from ..programs.config import Config
from .addresses import is_loopback

PID_FILE = "serve.pid"
STOP_WAIT_SECONDS = 30   # how long `engine serve stop` waits for the service to finish its answers
STOP_POLL_SECONDS = 0.1
LISTEN_BACKLOG = 64


class ServeOptions(msgspec.Struct, frozen=True):
    """What `engine serve` runs: the database (a resolved URL: engine.db.connection.resolve_url),
    where the web view listens, and the delivery to the controls: FTP on ftp_host:ftp_port (None:
    no FTP), request folders under `requests` for `request_machines` (None: none). `config`: the
    settings file (machines' line endings and FTP secret variables), the web view's too (a runner's
    request makes the same files)."""
    database_url: str
    host: str = "127.0.0.1"
    port: int = 8080
    ftp_host: str | None = None
    ftp_port: int | None = None
    requests: str | None = None
    request_machines: tuple[str, ...] = ()
    config: Config = Config()

    @property
    def address(self) -> str:
        """What to open in a browser."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"http://{host}:{self.port}/"

    @property
    def needs_login(self) -> bool:
        """Only the local user reaches a loopback address; anyone on the network reaches the others."""
        return not is_loopback(self.host)


class ServiceStopped(Exception):
    """`engine serve stop` asked the service to end (SIGTERM): a normal end, not a failure."""


def serve(options: ServeOptions, said: Callable[[str], None]) -> None:
    """Run the service until stopped; `said` gets the address to open, then how it ended.
    EngineError (nothing started) if another service runs or the address cannot be bound."""
    with PidFile() as held:
        listening = bound_socket(options.host, options.port)
        held.write(f"{os.getpid()} {options.address}\n")
        held.flush()
        try:
            with contextlib.ExitStack() as delivery:
                for part in _delivery_parts(options, said):
                    delivery.callback(part.close)
                _run(options, listening, said)
        finally:
            listening.close()


def _delivery_parts(options: ServeOptions, said: Callable[[str], None]) -> Iterator:
    """The FTP server and the request folders asked for, each started and said; a part that
    cannot start (a port in use, a root that does not exist) stops the service before it serves."""
    if options.ftp_port is not None:
        from .ftp import start_ftp_server

        ftp = start_ftp_server(options.database_url, options.config, options.ftp_host or options.host, options.ftp_port)
        yield ftp
        said(f"FTP for the controls on {options.ftp_host or options.host}:{ftp.port}; each machine logs in with "
             "its name and the secret in ENGINE_FTP_SECRET_<MACHINE> (or the variable its config table's "
             "ftp_secret_env names); a machine with none set cannot log in")
    if options.requests is not None:
        from .request_folder import start_request_folder

        yield start_request_folder(options.requests, list(options.request_machines), options.database_url,
                                   options.config)
        said(f"request folders under {options.requests} for {', '.join(options.request_machines)}")


def _run(options: ServeOptions, listening: socket.socket, said: Callable[[str], None]) -> None:
    import uvicorn

    from .web.app import create_app

    login = "; every page asks for a PostgreSQL login" if options.needs_login else ""
    if options.needs_login:
        from .web.auth import unchecked_logins

        refused = unchecked_logins(options.database_url)
        if refused is not None:   # said, not refused: FTP and the request folders serve the controls anyway
            said(refused)
    app = create_app(options.database_url, require_login=options.needs_login,
                     session_secret=secrets.token_urlsafe(32) if options.needs_login else None,
                     on_ready=lambda: said(f"serving the web view at {options.address}{login}; stop it with "
                                           "Ctrl-C or `engine serve stop`"), config=options.config)
    server = uvicorn.Server(uvicorn.Config(app, log_level="warning", lifespan="on"))
    # uvicorn catches both signals to finish the answers under way, then raises them again with the
    # handlers it found: Ctrl-C as KeyboardInterrupt (exit 130, even where the shell started the
    # service ignoring it), `engine serve stop` as ServiceStopped
    previous = {number: signal.signal(number, handler) for number, handler in
                ((signal.SIGINT, signal.default_int_handler), (signal.SIGTERM, _stopped))}
    try:
        server.run(sockets=[listening])
    except ServiceStopped:
        said("stopped (engine serve stop)")
        return
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
    if not server.started:
        raise EngineError(f"the web view at {options.address} did not start (its database could not be "
                          "opened; the lines above say why); check `engine db status`")


def _stopped(signum, frame) -> None:
    raise ServiceStopped()


def bound_socket(host: str, port: int) -> socket.socket:
    """A socket listening on host:port (requests wait in its backlog until the app answers);
    EngineError naming the address if it cannot be had."""
    try:
        family = socket.AF_INET6 if ":" in host else socket.AF_INET
        listening = socket.socket(family, socket.SOCK_STREAM)
        listening.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        listening.bind((host, port))
        listening.listen(LISTEN_BACKLOG)
    except OSError as error:
        listening.close()
        raise EngineError(f"cannot listen on {host}:{port} ({error.strerror or error}); give another "
                          "--port, or --host an address of this computer") from None
    return listening


class PidFile:
    """The pid file, created and locked for the life of the service, removed at its end."""

    def __init__(self):
        self.path = pid_path()
        self.file: IO[str] | None = None

    def __enter__(self) -> IO[str]:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        opened = open(self.path, "a+", encoding="utf-8")
        try:
            fcntl.flock(opened, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            opened.seek(0)
            running = opened.read().strip()
            opened.close()
            raise EngineError(f"engine serve already runs (pid and address: {running or 'starting'}); stop it "
                              "with `engine serve stop` first") from None
        opened.truncate(0)
        self.file = opened
        return opened

    def __exit__(self, *exc) -> None:
        assert self.file is not None
        self.path.unlink(missing_ok=True)   # still locked: no other service can hold this name meanwhile
        self.file.close()


def pid_path() -> Path:
    return runtime_folder() / PID_FILE


def stop_service() -> str:
    """Ask the running service to end (SIGTERM) and wait until it has; → what was stopped.
    EngineError if none runs."""
    path = pid_path()
    running = _running(path)
    if running is None:
        raise EngineError(f"no engine serve is running (no service holds {path}); nothing stopped")
    pid, address = running
    os.kill(pid, signal.SIGTERM)
    deadline = time.monotonic() + STOP_WAIT_SECONDS
    while _running(path) is not None:
        if time.monotonic() > deadline:
            raise EngineError(f"engine serve (pid {pid}) did not end within {STOP_WAIT_SECONDS} s of being "
                              f"asked; end it with `kill {pid}`")
        time.sleep(STOP_POLL_SECONDS)
    return f"stopped engine serve (pid {pid}) at {address}"


def _running(path: Path) -> tuple[int, str] | None:
    """(pid, address) of the service holding the pid file's lock, or None."""
    try:
        opened = open(path, encoding="utf-8")
    except FileNotFoundError:
        return None
    with opened:
        try:
            fcntl.flock(opened, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:   # held: the service runs
            pid, _, address = opened.read().strip().partition(" ")
            return (int(pid), address) if pid.isdigit() else None
        return None   # left by a service that ended without removing it
