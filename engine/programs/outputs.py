"""Program files in --out: written only after their programs are committed, each whole or absent.

A file in --out is what an operator loads into the machine, so it must be a program the
database holds, byte for byte. Storing runs in a transaction of its own that commits for
real (files_after_commit); psycopg makes `conn.transaction()` inside an open transaction a
mere savepoint, so a connection already inside its caller's transaction is refused when
files are asked for, rather than writing them before the caller's COMMIT. After the COMMIT
each file is written unnamed (Linux O_TMPFILE) and given its name in one step (linkat), so
a kill at any moment leaves each file complete or absent and no temporary file; --force
removes the old file just before the new one is linked (a kill in between leaves no file).
Where O_TMPFILE is not supported the file is written under a hidden temporary name first,
which a kill at that moment can leave behind.

Files are refused before anything is stored: a name that is not an 840D program name, a
name that would land outside --out, two programs of one run whose names differ only in case
(the control does not tell case), and an existing file without --force.

A file is written with the layout of its template version (issue 17: the class's line_ending and
final_newline as that version records them, template_version_rows; LF with a final newline unless the
class was imported from a file that had another), so an
imported program comes back byte for byte. A line ending configured for the program's machine
(the config file, set for the block by `line_endings(...)`; engine.programs.config) replaces the
class's line ending in that machine's files, for a control that wants CR LF; the final newline
stays the class's. Only the bytes of the file change, never the stored lines.
"""
from __future__ import annotations

import contextlib
import contextvars
import errno
import os
import secrets
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import psycopg
from psycopg.pq import TransactionStatus

from ..errors import EngineError
from ..names import checked
from ..nc.layout import NcLayout, nc_text
from .options import Output

if TYPE_CHECKING:
    from ..db.connection import Connection

SUFFIX = ".MPF"
# errno of open(O_TMPFILE) where the kernel or the file system does not support it
NO_TMPFILE = (errno.EOPNOTSUPP, errno.EISDIR, errno.EINVAL, errno.ENOENT)
PROC_FD = Path("/proc/self/fd")
# machine name -> the line ending configured for its files, or None (its class's)
CONFIGURED_ENDING: contextvars.ContextVar[Callable[[str], str | None] | None] = contextvars.ContextVar(
    "configured_ending", default=None)


class ProgramFiles:
    """The files of one run: checked when planned (before storing), written after the COMMIT.
    A batch (--gears, --jobs, --all) always writes into the folder --out, made if missing, however
    many programs it makes; one program is written to the file --out unless --out is a folder
    or ends with /."""

    def __init__(self, out, force: bool = False, batch: bool = False):
        self.out = Path(out) if out is not None else None
        self.force = force
        self.folder = batch or (out is not None and str(out).endswith(os.sep))
        self.texts: dict[Path, bytes] = {}
        self.paths: dict[str, Path] = {}
        self.layouts: dict[str, NcLayout] = {}

    def plan(self, programs: list[tuple[str, list[str]]],
             layouts: dict[str, NcLayout] | None = None) -> dict[str, str]:
        """{program name: path} for (name, lines) of each program, each file written with its
        layout by name (file_layouts; LF and a final newline if none is given); EngineError if
        any file cannot be written."""
        if self.out is None or not programs:
            return {}
        paths = self._targets([name for name, _ in programs])
        self._refuse_existing(list(paths.values()))
        _refuse_unwritable(paths[programs[0][0]].parent)
        self.layouts = layouts or {}
        self.texts = {paths[name]: self._bytes(name, lines) for name, lines in programs}
        self.paths = paths
        return {name: str(path) for name, path in paths.items()}

    def replace_texts(self, stored: dict[str, list[str]]) -> None:
        """The planned files hold the programs as stored (with their lineage line), by program name."""
        for name, lines in stored.items():
            if name in self.paths:
                self.texts[self.paths[name]] = self._bytes(name, lines)

    def _bytes(self, name: str, lines: list[str]) -> bytes:
        try:
            return nc_text(lines, self.layouts.get(name, NcLayout())).encode("ascii")
        except UnicodeEncodeError:
            raise EngineError(f"program {name} has non-ASCII characters; the control reads ASCII; nothing stored") \
                from None

    def _targets(self, names: list[str]) -> dict[str, Path]:
        """One program: --out is the file (unless a folder is meant); a batch: --out is their folder."""
        out = self.out
        assert out is not None   # write() plans files only for an --out
        if len(names) == 1 and not self.folder and not out.is_dir():
            return {names[0]: out}
        if out.exists() and not out.is_dir():
            raise EngineError(f"--out {out} is a file; give a folder for a batch of programs")
        _refuse_same_program_twice(names, out)
        return {name: _inside(out, name) for name in names}

    def _refuse_existing(self, targets: list[Path]) -> None:
        """An existing file is replaced only with --force; a file naming the same program in
        other case (the control does not tell case) is never replaced, nor kept beside it."""
        in_folder = _entries_by_program(targets[0].parent)
        for target in targets:
            other = next((entry for entry in in_folder.get(target.name.upper(), ()) if entry != target.name), None)
            if other is not None:
                raise EngineError(f"{target.parent / other} is there already, and the control reads it as the same "
                                  f"program as {target.name} (it does not tell upper from lower case): remove or "
                                  "rename it; nothing stored")
        existing = [target for target in targets if target.name in in_folder.get(target.name.upper(), ())]
        if existing and not self.force:
            more = f" (and {len(existing) - 1} more of this run's files)" if len(existing) > 1 else ""
            raise EngineError(f"{existing[0]} exists{more}; nothing stored: give --force to replace it, "
                              "or another --out")

    def write(self) -> None:
        """After the COMMIT: every planned file, or (on an error) none of this run's files."""
        written: list[Path] = []
        try:
            for target, data in self.texts.items():
                target.parent.mkdir(parents=True, exist_ok=True)
                _place(target, data, self.force)
                written.append(target)
        except OSError as error:
            for path in written:
                with contextlib.suppress(OSError):
                    os.unlink(path)
            raise EngineError(f"the program(s) are stored, but writing {error.filename or target} failed: "
                              f"{error.strerror}; no file of this run was kept") from None


@contextlib.contextmanager
def files_after_commit(conn: Connection, output: Output, batch: bool = False):
    """Yield ProgramFiles for the block, which runs in a transaction that commits for real when
    the block ends; only then are the planned files written. Without --out (output.out None) the
    block may run inside the caller's transaction (a savepoint), as nothing is written."""
    files = ProgramFiles(output.out, output.force, batch)
    if output.out is not None and conn.info.transaction_status != TransactionStatus.IDLE:
        raise EngineError("program files are written only after their programs are committed, but this "
                          "connection is inside a transaction its caller commits: commit first, or store without --out")
    with _committed(conn):
        yield files
    files.write()


@contextlib.contextmanager
def _committed(conn: Connection):
    """conn.transaction(), with a failed COMMIT said in one line (no file is written then)."""
    transaction = conn.transaction()
    transaction.__enter__()
    try:
        yield
    except BaseException as error:
        transaction.__exit__(type(error), error, error.__traceback__)
        raise
    try:
        transaction.__exit__(None, None, None)
    except psycopg.Error as error:
        raise commit_failure(error) from error


def _inside(folder: Path, name: str) -> Path:
    """The file of program `name` in `folder`; refused unless it is an 840D name that stays there."""
    checked("program", name, "program name", "set job.params.program_name in SQL")
    target = folder / f"{name}{SUFFIX}"
    if target.resolve().parent != folder.resolve():
        raise EngineError(f"program name {name!r} would write {target.resolve()}, outside --out {folder}")
    return target


def _refuse_same_program_twice(names: list[str], out: Path) -> None:
    """The control does not tell case: GEAR42 and gear42 are one program, so one file."""
    folded = [name.upper() for name in names]
    twice = sorted({name for name, key in zip(names, folded) if folded.count(key) > 1}) \
        if len(set(folded)) < len(folded) else []
    if twice:   # one file would silently replace the other (jobs of one gear made again, say)
        raise EngineError(f"{len(folded) - len(set(folded)) + 1} programs of this batch are named {twice[0]}, so "
                          f"their files would replace each other in {out}; make them without --out, or one at a time")


def _entries_by_program(folder: Path) -> dict[str, list[str]]:
    """The names in the folder (none if it does not exist yet), by the program they name: upper case."""
    try:
        entries = os.listdir(folder)
    except (FileNotFoundError, NotADirectoryError):
        return {}
    by_program: dict[str, list[str]] = {}
    for entry in entries:
        by_program.setdefault(entry.upper(), []).append(entry)
    return by_program


def _refuse_unwritable(folder: Path) -> None:
    """Checked before storing: the folder (or the nearest folder above it that exists) takes files."""
    existing = next(path for path in (folder, *folder.parents) if path.exists())
    if not existing.is_dir() or not os.access(existing, os.W_OK | os.X_OK):
        raise EngineError(f"cannot write files in {folder}: {existing} is not a folder this user may write; "
                          "nothing stored")


@contextlib.contextmanager
def line_endings(configured: Callable[[str], str | None]):
    """Files planned in the block for machine M end their lines with configured(M) ("\\n" or
    "\\r\\n"), where it gives one; else with their class's."""
    token = CONFIGURED_ENDING.set(configured)
    try:
        yield
    finally:
        CONFIGURED_ENDING.reset(token)


def file_layouts(programs) -> dict[str, NcLayout]:
    """{program name: the layout of its file} for programs (Planned or Encoded): the class's
    layout, its line ending replaced by the one configured for the program's machine, if any."""
    configured = CONFIGURED_ENDING.get()
    return {item.name: item.layout.ending_from(configured(item.machine) if configured else None)
            for item in programs}


def _place(target: Path, data: bytes, replace: bool) -> None:
    """Write `data` unnamed, then name it `target` in one step (no half-written or temporary file)."""
    folder = os.open(target.parent, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    try:
        unnamed = _unnamed_file(folder)
        if unnamed is None:
            return _place_through_temporary(target, data, replace)
        try:
            _write_all(unnamed, data)
            _link(unnamed, folder, target.name, replace)
        finally:
            os.close(unnamed)
    finally:
        os.close(folder)


def _unnamed_file(folder: int) -> int | None:
    """A new file without a name in the folder (mode 0666 less the umask), or None where the
    kernel, the file system or a missing /proc cannot give one."""
    if not hasattr(os, "O_TMPFILE") or not PROC_FD.is_dir():
        return None
    try:
        return os.open(".", os.O_TMPFILE | os.O_WRONLY | os.O_CLOEXEC, 0o666, dir_fd=folder)
    except OSError as error:
        if error.errno in NO_TMPFILE:
            return None
        raise


def _link(unnamed: int, folder: int, name: str, replace: bool) -> None:
    """Give the unnamed file its name; with `replace`, the old file goes just before."""
    if replace:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(name, dir_fd=folder)
    # linkat(…, AT_SYMLINK_FOLLOW) through /proc: os.link uses linkat only with a dir_fd; link(2) does not follow
    os.link(f"{PROC_FD}/{unnamed}", name, dst_dir_fd=folder, follow_symlinks=True)


def _place_through_temporary(target: Path, data: bytes, replace: bool) -> None:
    """Without O_TMPFILE: a hidden temporary file, renamed (--force) or linked (never over a file)."""
    temporary = target.with_name(f".{target.name}.{secrets.token_hex(6)}.tmp")
    descriptor = os.open(temporary, os.O_CREAT | os.O_EXCL | os.O_WRONLY | os.O_CLOEXEC, 0o666)
    try:
        try:
            _write_all(descriptor, data)
        finally:
            os.close(descriptor)
        if replace:
            os.replace(temporary, target)
        else:
            os.link(temporary, target)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temporary)


def _write_all(descriptor: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(descriptor, view):]


def commit_failure(error: psycopg.Error) -> EngineError:
    first_line = (str(error).strip().splitlines() or [type(error).__name__])[0]
    if isinstance(error, psycopg.OperationalError):
        return EngineError(f"the connection was lost while committing ({first_line}); no file written: "
                           "whether the program(s) were stored, `SELECT max(id) FROM program` tells")
    return EngineError(f"the database refused the commit ({first_line}); nothing stored, no file written")
