"""Which pg_dump and pg_restore fit the server (`engine db backup|restore`).

pg_dump refuses a server of a newer major version than its own ("server version mismatch"), and a
pg_restore of a newer version writes SQL an older server does not take, so the tools are chosen
by the server's major version (`SHOW server_version_num`): first the embedded package's own
binaries (the embedded server's version by construction), then each folder on PATH, then the
Debian/Ubuntu folders /usr/lib/postgresql/<major>/bin; pg_dump and pg_restore always from the same
folder. None matching is refused naming the versions found (issue 31: the system's pg_dump 15
refused the bundled PostgreSQL 18)."""
from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path
from typing import TYPE_CHECKING

import msgspec

from ..errors import EngineError
from .connection import scalar

if TYPE_CHECKING:
    from .connection import Connection

TOOLS = ("pg_dump", "pg_restore")
DEBIAN_FOLDERS = "/usr/lib/postgresql/{major}/bin"
CLIENT_VERSION = re.compile(r"\(PostgreSQL\)\s+(\d+)(?:\.(\d+))?")


class DumpTools(msgspec.Struct, frozen=True):
    """pg_dump and pg_restore of one folder, of the server's major version."""
    pg_dump: str
    pg_restore: str
    version: str   # the major version, "18" (or "9.6" before PostgreSQL 10)


def server_major(conn: Connection) -> str:
    """The server's major version from server_version_num (180001 → "18", 90624 → "9.6")."""
    number = int(scalar(conn.execute("SHOW server_version_num")))
    return str(number // 10000) if number >= 100000 else f"{number // 10000}.{number // 100 % 100}"


def client_major(program: Path) -> str | None:
    """The major version `program --version` reports, None if it does not run or say one."""
    try:
        said = subprocess.run([str(program), "--version"], capture_output=True, text=True, timeout=30,
                              check=False).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    match = CLIENT_VERSION.search(said)
    if match is None:
        return None
    return match.group(1) if int(match.group(1)) >= 10 else f"{match.group(1)}.{match.group(2)}"


def candidate_folders(major: str, path: str | None = None) -> list[Path]:
    """Where to look, in order: the embedded package's binaries, PATH (`path`: another search
    path), the Debian folder of `major`; each once."""
    from .embedded import bin_dir

    found: list[Path] = []
    for folder in [str(bin_dir()), *(path if path is not None else os.environ.get("PATH", "")).split(os.pathsep),
                   DEBIAN_FOLDERS.format(major=major)]:
        if folder and Path(folder) not in found:
            found.append(Path(folder))
    return found


def dump_tools(major: str, folders: list[Path]) -> DumpTools:
    """The first folder's pg_dump and pg_restore of version `major`; refused naming the versions found."""
    seen: dict[str, str] = {}
    for folder in folders:
        tools = [folder / name for name in TOOLS]
        if not all(tool.is_file() and os.access(tool, os.X_OK) for tool in tools):
            continue
        version = client_major(tools[0])
        if version == major and client_major(tools[1]) == major:
            return DumpTools(str(tools[0]), str(tools[1]), major)
        seen.setdefault(str(tools[0]), version or "of unknown version")
    return _refuse(major, seen)


def _refuse(major: str, seen: dict[str, str]) -> DumpTools:
    found = ", ".join(f"{path} is {version}" for path, version in seen.items()) or "none found"
    raise EngineError(f"no pg_dump/pg_restore of PostgreSQL {major}, the server's version ({found}): install "
                      f"the PostgreSQL {major} client (e.g. postgresql-client-{major}) or put its bin folder "
                      "first on PATH")


def tools_for(conn: Connection, path: str | None = None) -> DumpTools:
    """pg_dump and pg_restore of the connected server's major version."""
    major = server_major(conn)
    return dump_tools(major, candidate_folders(major, path))
