"""The FTP server of `engine serve` (issue 32; design notes §11; docs/guide/serving-programs.md):
Fanuc's Data Server (`M198` calls served from the host) and any DNC client that fetches by FTP.

Each machine logs in with its own name and a secret kept outside the config file (an environment
variable: the one its `[machines.<name>] ftp_secret_env` names, else ENGINE_FTP_SECRET_<NAME>, the
name upper-cased with every other character than a letter or digit an underscore); a machine with no
secret, an unknown one, anonymous, and two machines whose secret is read from one variable
(hobber-fanuc and hobber_fanuc by default) are refused. A machine sees one folder, its own: LIST and NLST
show engine.service.delivery.machine_files (nothing rendered), MDTM when its job last had a program
stored. RETR is engine.service.delivery.deliver: the program proved now, stored, recorded with the
client's address, and sent; a refusal is a 550 reply carrying its one-line reason, recorded too.
Every write (STOR, STOU, APPE, DELE, RNFR/RNTO, MKD, RMD, SITE CHMOD, MFMT) is refused: programs
reach a machine from the database only. SIZE answers 502 with its reason (a program's size is known
only once it is proved, at RETR), never 550: curl sends SIZE before RETR and takes
550 for "no such file", 502 for "size unknown" and fetches; SIZE is not in FEAT. REST, MLSD and MLST
are not offered: a program is sent whole. A
program is sent byte for byte in binary mode (TYPE I); in ASCII mode FTP itself sends each line end
as CR LF.

Threaded (pyftpdlib's ThreadedFTPServer): two machines fetching at once each have a thread, and
each request takes a connection of its own from a psycopg pool."""
from __future__ import annotations

import hmac
import io
import logging
import os
import posixpath
import re
import stat
import threading
import time
from typing import TYPE_CHECKING

from pyftpdlib.authorizers import AuthenticationFailed
from pyftpdlib.filesystems import AbstractedFS, FilesystemError
from pyftpdlib.handlers import FTPHandler
from pyftpdlib.handlers.ftp.producers import FileProducer
from pyftpdlib.servers import ThreadedFTPServer

from ..errors import EngineError
from ..programs.config import Config
from .delivery import MachineFile, as_ascii, deliver, machine_files

if TYPE_CHECKING:
    from psycopg_pool import ConnectionPool

LOG = logging.getLogger("engine.service.ftp")
SECRET_VARIABLE = "ENGINE_FTP_SECRET_{}"
WRITES = ("STOR", "STOU", "APPE", "DELE", "RNFR", "RNTO", "MKD", "XMKD", "RMD", "XRMD", "SITE CHMOD", "MFMT")
READ_PERMS = "elr"   # change folder (only its own), list, retrieve
POOL_SIZE = (1, 8)
LOOP_SECONDS = 0.1   # pyftpdlib's own is 1 s: every stop of the server waited for it
FAILED_LOGIN_DELAY = 3.0   # seconds before a failed login is answered (pyftpdlib's default), at most 3 a connection
WRITE_REFUSED = ("550 {command} refused: this server only sends programs; a program reaches a machine from the "
                 "database, proved when it is asked for")
# SIZE: 502, "not implemented", which curl takes as "size unknown" and goes on to RETR;
# 550 it takes as "no such file" and stops (exit 78). Nothing is made to answer it.
SIZE_UNKNOWN = "502 SIZE is not offered: a program's size is known only once it is proved; RETR makes and sends it"
# Not offered at all (not in FEAT, "500 not understood"): MLSD/MLST would show facts of files that are
# not on disk, and REST would resume a program made again meanwhile from the middle of another. SIZE
# is left out of FEAT too; pre_process_command answers it (SIZE_UNKNOWN).
NOT_OFFERED = ("MLSD", "MLST", "REST", "SIZE")


def secret_variable(config: Config, machine: str) -> str:
    """The environment variable holding the machine's FTP secret: its table's ftp_secret_env, else
    ENGINE_FTP_SECRET_<MACHINE> (what `engine serve` names for a machine that cannot log in)."""
    named = config.machines.get(machine, {}).get("ftp_secret_env")
    return named or SECRET_VARIABLE.format(re.sub(r"[^A-Z0-9]", "_", machine.upper()))


def machine_secret(config: Config, machine: str) -> str | None:
    """The machine's FTP secret from the environment, or None (it cannot log in). Never printed."""
    return os.environ.get(secret_variable(config, machine)) or None


class MachineAuthorizer:
    """Machines log in by name with their secret (compared in constant time); nothing else does."""

    def __init__(self, pool: ConnectionPool, config: Config):
        self.pool, self.config = pool, config

    def validate_authentication(self, username: str, password: str, handler) -> None:
        secret = machine_secret(self.config, username)
        if secret is None or not hmac.compare_digest(secret.encode(), password.encode()) or not self._own(username):
            raise AuthenticationFailed("Authentication failed: a machine logs in with its name and its secret.")

    def _own(self, machine: str) -> bool:
        """The machine exists and no other machine reads its secret's variable. hobber-fanuc and
        hobber_fanuc both read ENGINE_FTP_SECRET_HOBBER_FANUC by default: one secret would log in
        as either (the adversary of issue 32), so a shared variable is nobody's; said in the log."""
        with self.pool.connection() as conn:
            names = [row[0] for row in conn.execute("SELECT name FROM machine")]
        variable = secret_variable(self.config, machine)
        sharing = [name for name in names if name != machine and secret_variable(self.config, name) == variable]
        if sharing:
            LOG.warning("machine %s may not log in: machine %s reads its secret's variable %s too; give each its "
                        "own with ftp_secret_env in the config file", machine, sharing[0], variable)
        return machine in names and not sharing

    def has_user(self, username: str) -> bool:
        return machine_secret(self.config, username) is not None

    def has_perm(self, username: str, perm: str, path=None) -> bool:
        return perm in READ_PERMS

    def get_perms(self, username: str) -> str:
        return READ_PERMS

    def get_home_dir(self, username: str) -> str:
        return "/"

    def get_msg_login(self, username: str) -> str:
        return f"machine {username}: the programs it may load"

    def get_msg_quit(self, username: str) -> str:
        return "Goodbye."

    def impersonate_user(self, username: str, password: str) -> None:
        pass

    def terminate_impersonation(self, username: str) -> None:
        pass


class MachineFolder(AbstractedFS):
    """The machine's one virtual folder, "/": its listed programs, no subfolders, nothing on disk."""

    def files(self) -> dict[str, MachineFile]:
        handler = self.cmd_channel
        with handler.pool.connection() as conn:
            return {entry.name: entry for entry in machine_files(conn, handler.username)}

    def ftpnorm(self, ftppath: str) -> str:
        return posixpath.normpath(posixpath.join(self.cwd, ftppath)) if ftppath else self.cwd

    def ftp2fs(self, ftppath: str) -> str:
        return self.ftpnorm(ftppath)

    def fs2ftp(self, fspath: str) -> str:
        return fspath

    def validpath(self, path: str) -> bool:
        return path == "/" or posixpath.dirname(path) == "/"

    def realpath(self, path: str) -> str:
        return path

    def isdir(self, path: str) -> bool:
        return path == "/"

    def isfile(self, path: str) -> bool:
        return posixpath.dirname(path) == "/" and posixpath.basename(path) in self.files()

    def islink(self, path: str) -> bool:
        return False

    def lexists(self, path: str) -> bool:
        return self.isdir(path) or self.isfile(path)

    def chdir(self, path: str) -> None:
        if path != "/":
            raise FilesystemError("a machine has one folder, its own: /")

    def listdir(self, path: str) -> list[str]:
        return list(self.files())

    def lstat(self, path: str) -> os.stat_result:
        return self.stat(path)

    def stat(self, path: str) -> os.stat_result:
        if path == "/":
            return os.stat_result((stat.S_IFDIR | 0o555, 0, 0, 2, 0, 0, 0, 0, 0, 0))
        found = self.files().get(posixpath.basename(path))
        if found is None:
            raise FilesystemError(f"{posixpath.basename(path)} is not a program of this machine; LIST shows them")
        changed = int(found.changed_at.timestamp())
        return os.stat_result((stat.S_IFREG | 0o444, 0, 0, 1, 0, 0, 0, changed, changed, changed))

    def getmtime(self, path: str) -> float:
        return self.stat(path).st_mtime

    def getsize(self, path: str) -> int:
        raise FilesystemError(SIZE_UNKNOWN[4:])

    def get_user_by_uid(self, uid) -> str:
        return "engine"

    def get_group_by_gid(self, gid) -> str:
        return "engine"


class ProgramHandler(FTPHandler):
    """The control connection of one machine; pool and config are set on the server's subclass."""
    abstracted_fs = MachineFolder
    proto_cmds = {name: command for name, command in FTPHandler.proto_cmds.items() if name not in NOT_OFFERED}
    pool: ConnectionPool
    config: Config
    use_gmt_times = True
    banner = "engine serve: programs proved when they are asked for"

    def pre_process_command(self, line: str, cmd: str, arg: str) -> None:
        command = f"SITE {arg.split(' ')[0].upper()}" if cmd == "SITE" and arg else cmd
        if self.authenticated and command in WRITES:
            self.respond(WRITE_REFUSED.format(command=command))
            self.log_cmd(command, arg, 550, "write refused")
            return
        if self.authenticated and command == "SIZE":
            self.respond(SIZE_UNKNOWN)
            return
        super().pre_process_command(line, cmd, arg)

    def ftp_RETR(self, file: str):
        """The program proved now and sent, or 550 with the one-line reason (both recorded)."""
        try:
            with self.pool.connection() as conn:
                delivered = deliver(conn, self.username, posixpath.basename(file), via="ftp", client=self.remote_ip,
                                    config=self.config)
        except EngineError as refusal:
            self.respond(f"550 {as_ascii(str(refusal))}")
            return None
        except Exception:   # a bug or a lost database: said in the log, never a traceback to the control
            LOG.exception("RETR %s by %s failed", file, self.username)
            self.respond("451 the program could not be made (an error of the server, in its log); try again")
            return None
        data = io.BytesIO(delivered.data)
        data.name = file   # pyftpdlib logs the file's name
        self.push_dtp_data(FileProducer(data, self._current_type), isproducer=True, file=data, cmd="RETR")
        return file


class FtpService:
    """A running FTP server: its port, and close() to stop it (joins its thread, closes its pool)."""

    def __init__(self, server: ThreadedFTPServer, thread: threading.Thread, pool: ConnectionPool):
        self.server, self.thread, self.pool = server, thread, pool

    @property
    def port(self) -> int:
        return int(self.server.address[1])

    def close(self) -> None:
        self.server.close_all()
        self.thread.join(timeout=30)
        self.pool.close()


def start_ftp_server(database_url: str, config: Config, host: str = "127.0.0.1", port: int = 0, *,
                     failed_login_delay: float = FAILED_LOGIN_DELAY) -> FtpService:
    """The FTP server on host:port (0: any free port), serving in a thread of its own. A failed
    login is answered after `failed_login_delay` seconds (a brake on guessing secrets)."""
    from psycopg_pool import ConnectionPool

    from ..db.json_numbers import read_bounded_json

    pool = ConnectionPool(database_url, min_size=POOL_SIZE[0], max_size=POOL_SIZE[1], configure=read_bounded_json,
                          open=False)
    pool.open(wait=True)
    handler = type("MachineHandler", (ProgramHandler,), {"pool": pool, "config": config,
                                                         "authorizer": MachineAuthorizer(pool, config),
                                                         "auth_failed_timeout": failed_login_delay})
    try:
        server = ThreadedFTPServer((host, port), handler)
    except OSError as error:
        pool.close()
        raise EngineError(f"the FTP server cannot listen on {host}:{port} ({error.strerror or error})") from None
    # the loop looks for its end every LOOP_SECONDS: close() (engine serve stopping) waits that long at most
    thread = threading.Thread(target=server.serve_forever, kwargs={"handle_exit": False, "timeout": LOOP_SECONDS},
                              name="engine-ftp", daemon=True)
    thread.start()
    return FtpService(server, thread, pool)


def wait_until_stopped(service: FtpService) -> None:
    """Blocks while the server runs (engine serve's foreground); Ctrl-C reaches the caller."""
    while service.thread.is_alive():
        time.sleep(0.5)
