"""Program files in --out: written only after their programs are committed, each whole or absent.

A file in --out is what an operator loads into the machine, so it must be a program the
database holds, byte for byte. Storing runs in a transaction of its own that commits for
real (files_after_commit); psycopg makes `conn.transaction()` inside an open transaction a
mere savepoint, so a connection already inside its caller's transaction is refused when
files are asked for, rather than writing them before the caller's COMMIT. After the COMMIT
the files are placed by engine.programs.file_writes (issue 26): all written in full first,
then each given its name, an old file replaced in one step (rename), so a failure leaves
every earlier file as it was and a kill leaves each file old or new, never missing.

Files are refused before anything is stored: a name that is not an 840D program name, a
name that would land outside --out, two programs of one run whose names differ only in case
(the control does not tell case), an existing file without --force, and a target that is a
symbolic link or not a regular file. What goes wrong after the COMMIT (a disk full, the folder
swapped for a link) is StoredNotWritten: the CLI's exit code 3, "stored, not written", naming
the stored programs and the files not written (exit 1 always means nothing stored).

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
import os
import stat
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import psycopg
from psycopg.pq import TransactionStatus

from ..errors import EngineError
from ..names import checked
from ..nc.layout import NcLayout, nc_text
from ..nc.lineage import LINEAGE_SHAPE
from .options import Output

if TYPE_CHECKING:
    from ..db.connection import Connection
    from .file_writes import FolderSeen, NotWritten

SUFFIX = ".MPF"
STORED_NOT_WRITTEN = 3   # the CLI's exit code when programs were committed but their files not written
# machine name -> the line ending configured for its files, or None (its class's)
CONFIGURED_ENDING: contextvars.ContextVar[Callable[[str], str | None] | None] = contextvars.ContextVar(
    "configured_ending", default=None)


class ProgramFiles:
    """The files of one run: checked when planned (before storing), written after the COMMIT.
    A batch (--gears, --jobs, --all) always writes into the folder --out, however many programs
    it makes; one program is written to the file --out unless --out is a folder or ends with /.
    The folder must exist unless `mkdir` (--mkdir) asks for it to be made."""

    def __init__(self, out, force: bool = False, batch: bool = False, mkdir: bool = False):
        self.out = Path(out) if out is not None else None
        self.force, self.mkdir = force, mkdir
        self.folder = batch or (out is not None and str(out).endswith(os.sep))
        self.texts: dict[Path, bytes] = {}
        self.paths: dict[str, Path] = {}
        self.layouts: dict[str, NcLayout] = {}
        self.ids: dict[Path, int | None] = {}   # the stored program of each file, from its lineage line
        self.seen: FolderSeen | None = None

    def plan(self, programs: list[tuple[str, list[str]]],
             layouts: dict[str, NcLayout] | None = None) -> dict[str, str]:
        """{program name: path} for (name, lines) of each program, each file written with its
        layout by name (file_layouts; LF and a final newline if none is given); EngineError if
        any file cannot be written."""
        if self.out is None or not programs:
            return {}
        from .file_writes import FolderSeen  # only where files are written (issue 28: start-up)

        try:   # a path the system refuses to look at (too long, a symlink loop, a file as a folder, no access)
            paths = self._targets([name for name, _ in programs])
            _refuse_missing_folder(paths[programs[0][0]].parent, self.mkdir)
            self._refuse_existing(list(paths.values()))
            _refuse_unwritable(paths[programs[0][0]].parent)
            self.seen = FolderSeen.now(paths[programs[0][0]].parent)
        except (OSError, RuntimeError) as error:   # RuntimeError: Path.resolve's symlink loop before 3.13
            reason = getattr(error, "strerror", None) or str(error)
            raise EngineError(f"--out {_short(self.out)}: cannot be used ({reason}); nothing stored") from None
        self.layouts = layouts or {}
        self.texts = {paths[name]: self._bytes(name, lines) for name, lines in programs}
        self.paths = paths
        return {name: str(path) for name, path in paths.items()}

    def replace_texts(self, stored: dict[str, list[str]]) -> None:
        """The planned files hold the programs as stored (with their lineage line), by program name."""
        for name, lines in stored.items():
            if name in self.paths:
                self.texts[self.paths[name]] = self._bytes(name, lines)
                self.ids[self.paths[name]] = _program_id(lines)

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
        _refuse_unreplaceable(existing)
        if existing and not self.force:
            more = f" (and {len(existing) - 1} more of this run's files)" if len(existing) > 1 else ""
            raise EngineError(f"{existing[0]} exists{more}; nothing stored: give --force to replace it, "
                              "or another --out")

    def write(self) -> None:
        """After the COMMIT: every planned file, or StoredNotWritten naming the programs stored and
        the files not written (engine.programs.file_writes: none of them if it failed before any
        was named)."""
        if not self.texts or self.seen is None:
            return
        from .file_writes import NotWritten, write_files

        try:
            write_files(self.seen, {target.name: data for target, data in self.texts.items()}, self.force)
        except NotWritten as error:
            raise StoredNotWritten(error, self.texts, self.ids) from None


class StoredNotWritten(EngineError):
    """Programs committed, but (some of) their files not written: exit code 3, not 1 (which says
    nothing was stored). The message names the stored program ids, the cause, the files written
    and not written; `problems` lists the files not written when there are several."""
    exit_code = STORED_NOT_WRITTEN

    def __init__(self, error: NotWritten, texts: dict[Path, bytes], ids: dict[Path, int | None]):
        missing = [target for target in texts if target.name not in error.written]
        written = [target for target in texts if target.name in error.written]
        self.program_ids = sorted(program_id for program_id in ids.values() if program_id is not None)
        self.not_written = [str(target) for target in missing]
        self.problems = [f"not written: {target} (program {ids.get(target, '?')})" for target in missing] \
            if len(missing) > 1 else []
        super().__init__(_not_written_message(error, missing, written, self.program_ids, ids))


def _not_written_message(error: NotWritten, missing: list[Path], written: list[Path], ids: list[int],
                         by_file: dict[Path, int | None]) -> str:
    stored = f"program {ids[0]} is stored" if len(ids) == 1 else f"programs {_id_runs(ids)} are stored" if ids \
        else "the programs are stored"
    if not missing:   # every file named, then the folder found moved or its names not synced
        return (f"{stored} and written, but {error.path}: {error.cause}; check that the files are where the "
                "machine reads them, or run the command again")
    kept = "every file there is as it was" if not written else \
        f"replaced or written: {', '.join(target.name for target in written)}"
    files = f"{missing[0].name} (program {by_file.get(missing[0], '?')})" if len(missing) == 1 \
        else f"{len(missing)} files (below)"
    return (f"{stored}, but not written to files: {error.path}: {error.cause}; not written: {files}; {kept}. "
            "Fix the cause and run the command again (it stores new programs; --force replaces files); "
            "`engine programs show ID` shows a stored one")


def _id_runs(ids: list[int]) -> str:
    """812, 815–900: the ids, consecutive runs joined (a batch draws them in a row)."""
    runs: list[list[int]] = []
    for program_id in ids:
        if runs and program_id == runs[-1][-1] + 1:
            runs[-1].append(program_id)
        else:
            runs.append([program_id])
    return ", ".join(str(run[0]) if len(run) == 1 else f"{run[0]}–{run[-1]}" for run in runs)


def _program_id(lines: list[str]) -> int | None:
    """The program id on the stored program's lineage line (every stored program has one)."""
    found = next((match for match in map(LINEAGE_SHAPE.search, lines) if match), None)
    return int(found.group(1)) if found is not None and found.group(1).isdigit() else None


def _refuse_unreplaceable(existing: list[Path]) -> None:
    """--force replaces a program file, never a link (the file it points to would be left as it
    was, or replaced elsewhere) nor a folder; checked before anything is stored."""
    for target in existing:
        mode = os.lstat(target).st_mode
        if stat.S_ISLNK(mode) or not stat.S_ISREG(mode):
            what = "a symbolic link" if stat.S_ISLNK(mode) else "not a regular file"
            raise EngineError(f"{target} is {what}, which the engine never replaces: remove it or give another "
                              "--out; nothing stored")


@contextlib.contextmanager
def files_after_commit(conn: Connection, output: Output, batch: bool = False):
    """Yield ProgramFiles for the block, which runs in a transaction that commits for real when
    the block ends; only then are the planned files written. Without --out (output.out None) the
    block may run inside the caller's transaction (a savepoint), as nothing is written."""
    files = ProgramFiles(output.out, output.force, batch, output.mkdir)
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


def _short(path: Path | None) -> str:
    """The path as given, cut to 80 characters (a name too long for the system is named, not printed whole)."""
    text = str(path)
    return text if len(text) <= 80 else text[:77] + "..."


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


def _refuse_missing_folder(folder: Path, mkdir: bool) -> None:
    """A folder that does not exist is a typo until --mkdir says otherwise (issue 31: a misspelt
    share path quietly became a new folder of programs nobody found); checked before storing."""
    if not mkdir and not folder.is_dir():
        raise EngineError(f"--out: the folder {_short(folder)} does not exist; nothing stored; check the path, "
                          "or give --mkdir to create it")


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


def commit_failure(error: psycopg.Error) -> EngineError:
    first_line = (str(error).strip().splitlines() or [type(error).__name__])[0]
    if isinstance(error, psycopg.OperationalError):
        return EngineError(f"the connection was lost while committing ({first_line}); no file written: "
                           "whether the program(s) were stored, `SELECT max(id) FROM program` tells")
    return EngineError(f"the database refused the commit ({first_line}); nothing stored, no file written")
