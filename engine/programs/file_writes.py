"""The files of one run placed in their folder (issue 26): every file written in full first, then
each given its name, so a run whose files cannot all be written replaces none.

An operator loads a file from the folder into the machine at any moment, so a file that exists
must never be missing or half-written, not even for an instant: an old file is replaced by
rename(2) (`os.replace`), which gives the new file the old one's name in one step; the old file
stays until then. The files are written in two stages:

1. Each file is written unnamed (Linux O_TMPFILE) in the folder and synced (fsync: a full disk
   or a failed write says so here, not later); each target is checked (no symbolic link, no
   folder, no file that appeared without --force). A failure here names nothing: every old
   file is as it was and no temporary is left, even after a kill (an unnamed file vanishes
   with its process).
2. Only then is each given its name: a new file linked to it (linkat, which never replaces), an
   old one replaced through a hidden temporary name (`.NAME.MPF.<hex>.tmp`, renamed at once
   onto the target; a kill between the two leaves that hidden file beside the old one, which
   is whole). A failure here (rare: the names are in a folder already checked) says exactly
   which files were replaced and which not.

The folder is opened once, at the start, and every step is relative to that descriptor, so the
files go into the folder that was checked when the run was planned: a folder swapped for
another, or for a symbolic link, between the plan and the files is refused before any file is
named, and one swapped while they are named is said after. Where O_TMPFILE is not supported (or
the files outnumber the descriptors a process may hold) stage 1 writes hidden temporary files
instead, which a kill at that moment can leave behind.
"""
from __future__ import annotations

import contextlib
import errno
import os
import resource
import secrets
import stat
from pathlib import Path

import msgspec

# errno of open(O_TMPFILE) where the kernel or the file system does not support it
NO_TMPFILE = (errno.EOPNOTSUPP, errno.EISDIR, errno.EINVAL, errno.ENOENT)
PROC_FD = Path("/proc/self/fd")
SPARE_DESCRIPTORS = 64   # kept free for the database connection, the terminal and Python itself


class FolderSeen(msgspec.Struct, frozen=True):
    """The folder of a run's files as the plan saw it: its device and inode (None if it did not
    exist yet) and whether the path was a symbolic link then (a shop's link to its share stays
    allowed; a real folder swapped for a link is not)."""
    path: Path
    identity: tuple[int, int] | None
    link: bool

    @classmethod
    def now(cls, path: Path) -> FolderSeen:
        try:
            seen = os.stat(path)
        except (FileNotFoundError, NotADirectoryError):
            return cls(path, None, False)
        return cls(path, (seen.st_dev, seen.st_ino), path.is_symlink())


class NotWritten(Exception):
    """Files of a run not written: why (`cause`), the path it concerns, and the names of the
    files given their new content before it happened (`written`, in order)."""

    def __init__(self, cause: str, path: Path | str, written: list[str] | None = None):
        self.cause, self.path, self.written = cause, str(path), list(written or [])
        super().__init__(f"{self.path}: {cause}")


class Staged(msgspec.Struct):
    """One file written in full, not yet named: an unnamed file's descriptor, or a hidden name."""
    name: str
    descriptor: int | None = None
    temporary: str | None = None
    replaces: bool = False


def write_files(seen: FolderSeen, texts: dict[str, bytes], replace: bool) -> None:
    """Every file of `texts` (name in the folder -> bytes) written, or NotWritten saying which
    were and why (see the module's docstring)."""
    try:
        seen.path.mkdir(parents=True, exist_ok=True)
        folder = _opened(seen)
    except OSError as error:
        raise NotWritten(error.strerror or str(error), error.filename or seen.path) from None
    try:
        staged = _staged(folder, seen, texts, replace)
        _named(folder, seen, staged)
    finally:
        os.close(folder)


def _opened(seen: FolderSeen) -> int:
    """The folder's descriptor; NotWritten if it is not the folder the plan saw."""
    flags = os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC | (0 if seen.link else os.O_NOFOLLOW)
    try:
        folder = os.open(seen.path, flags)
    except OSError as error:
        if error.errno in (errno.ELOOP, errno.ENOTDIR):
            raise NotWritten("it was replaced by a symbolic link or a file after the programs were planned; "
                             "nothing written through it", seen.path) from None
        raise
    if seen.identity is not None and _identity(os.fstat(folder)) != seen.identity:
        os.close(folder)
        raise NotWritten("it is another folder than the one planned (moved or swapped meanwhile); "
                         "nothing written into it", seen.path)
    return folder


def _identity(status: os.stat_result) -> tuple[int, int]:
    return status.st_dev, status.st_ino


def _staged(folder: int, seen: FolderSeen, texts: dict[str, bytes], replace: bool) -> list[Staged]:
    """Stage 1: every file written in full and synced, nothing named; on any failure the
    staged files are discarded and NotWritten raised (no file written)."""
    staged: list[Staged] = []
    unnamed = _room_for(len(texts))
    path = seen.path
    try:
        for name, data in texts.items():
            path = seen.path / name
            replaces = _checked_target(folder, path, name, replace)
            staged.append(_write_one(folder, name, data, unnamed, replaces))
        _still_there(folder, seen)
    except OSError as error:
        _discard(folder, staged)
        raise NotWritten(error.strerror or str(error), path) from None
    except BaseException:
        _discard(folder, staged)
        raise
    return staged


def _checked_target(folder: int, path: Path, name: str, replace: bool) -> bool:
    """True if the target exists and is to be replaced; NotWritten if it is a link, not a
    regular file, or appeared since the plan without --force."""
    try:
        status = os.lstat(name, dir_fd=folder)
    except FileNotFoundError:
        return False
    if stat.S_ISLNK(status.st_mode):
        raise NotWritten("it is a symbolic link; the engine does not write through links", path)
    if not stat.S_ISREG(status.st_mode):
        raise NotWritten("it is not a regular file (a folder?), so it is not replaced", path)
    if not replace:
        raise NotWritten("it appeared after the programs were planned; give --force to replace it", path)
    return True


def _room_for(count: int) -> bool:
    """True if this process may hold `count` unnamed files open at once (its soft limit raised
    toward the hard one if need be); else stage 1 uses hidden temporary names."""
    if not hasattr(os, "O_TMPFILE") or not PROC_FD.is_dir():
        return False
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    wanted = count + SPARE_DESCRIPTORS
    if soft != resource.RLIM_INFINITY and soft < wanted:
        with contextlib.suppress(ValueError, OSError):
            resource.setrlimit(resource.RLIMIT_NOFILE, (min(wanted, hard) if hard != resource.RLIM_INFINITY
                                                        else wanted, hard))
        soft = resource.getrlimit(resource.RLIMIT_NOFILE)[0]
    return soft == resource.RLIM_INFINITY or soft >= wanted


def _write_one(folder: int, name: str, data: bytes, unnamed: bool, replaces: bool) -> Staged:
    """The file written in full and synced: unnamed if it may be, else under a hidden name."""
    descriptor = _unnamed_file(folder) if unnamed else None
    if descriptor is not None:
        item = Staged(name, descriptor=descriptor, replaces=replaces)
    else:
        temporary = _temporary_name(name)
        descriptor = os.open(temporary, os.O_CREAT | os.O_EXCL | os.O_WRONLY | os.O_CLOEXEC, 0o666, dir_fd=folder)
        item = Staged(name, temporary=temporary, replaces=replaces)
    try:
        _write_all(descriptor, data)
        os.fsync(descriptor)
    except BaseException:
        os.close(descriptor)
        with contextlib.suppress(OSError):
            if item.temporary:
                os.unlink(item.temporary, dir_fd=folder)
        raise
    if item.temporary:
        os.close(descriptor)
    return item


def _unnamed_file(folder: int) -> int | None:
    """A new file without a name in the folder (mode 0666 less the umask), or None where the
    kernel or the file system cannot give one."""
    try:
        return os.open(".", os.O_TMPFILE | os.O_WRONLY | os.O_CLOEXEC, 0o666, dir_fd=folder)
    except OSError as error:
        if error.errno in NO_TMPFILE:
            return None
        raise


def _temporary_name(name: str) -> str:
    return f".{name}.{secrets.token_hex(6)}.tmp"


def _write_all(descriptor: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(descriptor, view):]


def _still_there(folder: int, seen: FolderSeen) -> None:
    """NotWritten if the path no longer names the folder the files are being written into."""
    try:
        now = _identity(os.stat(seen.path))
    except OSError:
        now = None
    if now != _identity(os.fstat(folder)):
        raise NotWritten("it was moved or swapped for another folder or a link while the files were being "
                         "written", seen.path)


def _named(folder: int, seen: FolderSeen, staged: list[Staged]) -> None:
    """Stage 2: each staged file given its name, in order; NotWritten names those that were."""
    written: list[str] = []
    path = seen.path
    try:
        for item in staged:
            path = seen.path / item.name
            _name(folder, item)
            written.append(item.name)
        path = seen.path
        os.fsync(folder)   # the new names on disk, not only in the cache
        _still_there(folder, seen)
    except OSError as error:
        raise NotWritten(error.strerror or str(error), path, written) from None
    except NotWritten as error:
        error.written = written
        raise
    finally:
        _discard(folder, staged[len(written):])


def _name(folder: int, item: Staged) -> None:
    """A new file linked to its name (never over a file that appeared meanwhile); an old file
    replaced in one step (rename), never removed first."""
    if item.descriptor is not None and not item.replaces:
        _link_unnamed(folder, item, item.name)
        return
    if item.descriptor is not None:
        _link_unnamed(folder, item, _temporary_name(item.name))
    temporary = item.temporary
    assert temporary is not None   # staged under a hidden name, or just linked to one
    if item.replaces:
        os.replace(temporary, item.name, src_dir_fd=folder, dst_dir_fd=folder)
    else:
        os.link(temporary, item.name, src_dir_fd=folder, dst_dir_fd=folder, follow_symlinks=False)
        os.unlink(temporary, dir_fd=folder)
    item.temporary = None


def _link_unnamed(folder: int, item: Staged, name: str) -> None:
    """linkat(…, AT_SYMLINK_FOLLOW) through /proc: how an O_TMPFILE file gets a name (open(2));
    os.link uses linkat only with a dir_fd."""
    assert item.descriptor is not None
    os.link(f"{PROC_FD}/{item.descriptor}", name, dst_dir_fd=folder, follow_symlinks=True)
    os.close(item.descriptor)
    item.descriptor = None
    item.temporary = None if name == item.name else name


def _discard(folder: int, staged: list[Staged]) -> None:
    """The staged files not named: closed (an unnamed one vanishes) or their hidden name removed."""
    for item in staged:
        if item.descriptor is not None:
            with contextlib.suppress(OSError):
                os.close(item.descriptor)
            item.descriptor = None
        if item.temporary is not None:
            with contextlib.suppress(OSError):
                os.unlink(item.temporary, dir_fd=folder)
            item.temporary = None
