"""The request folder of `engine serve` (issue 32; design notes §11; docs/guide/serving-programs.md):
for controls that read programs from a network share, as an 840D does with `EXTCALL`.

One folder per machine under a root (`<root>/<machine>/`). A control asks by writing a request
file `<stem>.REQ` (stem: letters, digits and _, at most 24; a request of another stem is answered
`<stem>.ERR` saying so, recorded and logged; a symbolic link is never read nor answered) whose
one line names what it wants, ended by a new line: `JOB 17`, `GEAR 42` (that gear's newest stored
job on the machine), `O1042` or a name its FTP list shows (engine.service.delivery_names); a request
of more lines is refused (an 840D's WRITE appends to a request left unanswered). The engine answers
each request once:

0. the request is claimed: renamed `<stem>.DONE`, then read (a request written again meanwhile is
   a new file, answered at a later look);
1. the program, proved now (engine.service.delivery.deliver, via "folder"), is written next to it as
   `PG<program id>_<first 7 hex digits of the sha256 of its bytes>.MPF` (program_file_name): a name
   that changes with the bytes, so a control never takes another program's file, nor an older one,
   for its answer, and an 840D program name for every id below 10^14 (plants' ids included);
2. then `<stem>.RDY`, holding that file name, then the request's words as read (each line ended by
   a new line): the name the control waits for with `ISFILE`, known in advance, and what it
   answers, which the control compares with what it wrote; or, for a refusal, `<stem>.ERR` holding
   the one-line reason, then the request's words;
3. unless the control wrote a new `<stem>.REQ` meanwhile: then this answer is not written (the
   control would take it for the new request's), and the new request is answered instead.

Each file is written under a temporary name (a dot file, which is neither a program nor an answer),
flushed to disk (fsync) and given its name in one step (os.replace), so a control never reads a
half-written file. A request is taken only when it ends with a new line and has not changed since
the previous look (a writer still writing is waited for); before answering, an old `<stem>.RDY` or
`<stem>.ERR` is removed (the control removes it too, before it writes a request). `poll_once` looks
once (tests, and a loop in `engine serve`)."""
from __future__ import annotations

import hashlib
import logging
import os
import re
import stat
import threading
import uuid
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import msgspec

from ..errors import EngineError
from ..programs.config import Config
from .delivery import Delivered, as_ascii, deliver, one_line, record_refusal

if TYPE_CHECKING:
    from ..db.connection import Connection

# Any file named <stem>.REQ but a dot file (a temporary of ours, or hidden) is a request; one whose
# stem is not STEM is answered with a refusal naming the rule (it was left unanswered: the control
# timed out with no word why, the review of issue 32).
REQUEST = re.compile(r"(?P<stem>[^.].*)\.REQ", re.IGNORECASE | re.DOTALL)
STEM = re.compile(r"[A-Za-z0-9_]{1,24}")
BAD_STEM = ("request file {name!r} refused: its stem {why}; a request's stem is 1 to 24 letters, digits and _ "
            "(HOB1.REQ): rename it")
NAME_MAX = 255   # bytes of a file name on the shares the controls write to (ext4, NTFS, SMB)
MAX_REQUEST_BYTES = 1024   # a request's first line is read from its first KiB; a bound no control meets
READY, ERROR, DONE = ".RDY", ".ERR", ".DONE"
# The program file: PG, the program id, _, the first 7 hex digits of its bytes' sha256: two letters
# first and at most 24 characters, an 840D program name (docs/reference/hobbing.md §A1; EXTCALL
# calls it), for every id below 10^14 (14 digits: a plant's N·10^10 for N up to 9999, engine/plants).
# PRG<id>_<8 hex> was 25 characters from 13 digits on (the review of issue 32).
PROGRAM_FILE = "PG{program_id}_{digest}.MPF"
PROGRAM_FILE_HEX = 7
PROGRAM_ID_LIMIT = 10**14
POLL_SECONDS = 1.0
LOG = logging.getLogger("engine.service.request_folder")


class Answer(msgspec.Struct, frozen=True):
    """What one request got: the machine, the request file, the program file written or the refusal."""
    machine: str
    request: str
    program_file: str | None = None
    refusal: str | None = None


class RequestFolder:
    """The machines' request folders under `root`, answered on one database connection."""

    def __init__(self, root: str | os.PathLike, machines: list[str], database_url: str, config: Config):
        from ..db.connection import connect

        self.root, self.machines, self.config = Path(root), list(machines), config
        if not self.root.is_dir():
            raise EngineError(f"request folder root {self.root} does not exist; create it (the share the controls "
                              "write to)")
        self.database_url = database_url
        self.conn: Connection = connect(database_url)
        self._refuse_unknown_machines()
        for machine in self.machines:
            (self.root / machine).mkdir(exist_ok=True)
        self._seen: dict[Path, tuple[int, int]] = {}   # request -> (size, mtime_ns) at the previous look
        self._too_long: set[Path] = set()              # requests said in the log as never claimable

    def _refuse_unknown_machines(self) -> None:
        with self.conn.transaction():
            known = {row[0] for row in self.conn.execute("SELECT name FROM machine WHERE name = ANY(%s)",
                                                         (self.machines,))}
        unknown = [machine for machine in self.machines if machine not in known]
        if unknown:
            self.conn.close()
            raise EngineError(f"machine {unknown[0]} of the request folders does not exist; see `engine machines list`")

    def poll_once(self) -> list[Answer]:
        """Every complete request of every machine answered once, in name order."""
        if self.conn.closed or self.conn.broken:   # the database restarted: a new connection
            from ..db.connection import connect

            self.conn = connect(self.database_url)
        return [answer for machine in self.machines for answer in self._poll(machine)]

    def _poll(self, machine: str) -> list[Answer]:
        folder = self.root / machine
        requests = [(entry, found.group("stem")) for entry in sorted(folder.iterdir())
                    if (found := REQUEST.fullmatch(entry.name)) and not entry.is_symlink() and entry.is_file()]
        self._seen = {path: seen for path, seen in self._seen.items()   # requests gone meanwhile forgotten
                      if path.parent != folder or any(path == entry for entry, _ in requests)}
        return [answer for entry, stem in requests if (answer := self._taken(machine, entry, stem))]

    def _claimable(self, machine: str, request: Path, stem: str) -> bool:
        """The request can be claimed: `<stem>.DONE` is a name the share takes (a stem of 251 bytes
        or more cannot be; said in the log once, never answered)."""
        if len(os.fsencode(f"{stem}{DONE}")) <= NAME_MAX:
            return True
        if request not in self._too_long:
            self._too_long.add(request)
            LOG.warning("request %s of machine %s not answered: its name is too long to claim as %s; a request's "
                        "stem is 1 to 24 letters, digits and _", as_ascii(repr(request.name)[:80]), machine, DONE)
        return False

    def _taken(self, machine: str, request: Path, stem: str) -> Answer | None:
        """The request answered if complete, else None; a request the share will not let be looked at
        or answered (its answer's name taken by a folder, the request gone meanwhile) is said in the
        log and left for the next look, so it never stops the requests after it, of every machine
        (the adversary of issue 32 found one folder named A.RDY leaving all of them unanswered)."""
        try:
            if not self._claimable(machine, request, stem):
                return None
            return self._answer(machine, request, stem) if self._complete(request) else None
        except OSError as error:
            LOG.warning("request %s of machine %s not answered: %s", request.name, machine, error)
            return None

    def _complete(self, request: Path) -> bool:
        """Ends with a new line and unchanged since the previous look (else looked at again next time)."""
        status = request.lstat()
        now, before = (status.st_size, status.st_mtime_ns), self._seen.get(request)
        self._seen[request] = now
        if before != now:
            return False
        return status.st_size > MAX_REQUEST_BYTES or _read_request(request).endswith(b"\n")

    def _answer(self, machine: str, request: Path, stem: str) -> Answer | None:
        """The request answered: its old answer removed, the request claimed (renamed .DONE) and read,
        the program proved, then the answer written, unless the control asked again meanwhile.

        Claimed before it is read, so a request written again while this one is answered is a new
        file, answered at a later look, never renamed .DONE unread; and no answer is written once a
        new request is there, as the control waiting for it would take this one's answer for its own
        (the adversary of issue 32 had job 42's program named in the .RDY of a request for job 43)."""
        folder = self.root / machine
        for old in (READY, ERROR):
            (folder / f"{stem}{old}").unlink(missing_ok=True)
        claimed = folder / f"{stem}{DONE}"
        os.replace(request, claimed)
        self._seen.pop(request, None)
        words = _request_text(_read_request(claimed))
        try:
            delivered = self._delivered(machine, request.name, stem, words)
        except EngineError as refusal:
            answer = partial(_refused, folder, machine, request.name, stem, one_line(str(refusal)), words)
        else:
            answer = partial(_sent, folder, machine, request.name, stem, delivered, words)
        if request.exists():   # asked again meanwhile: this answer would be taken for that request
            LOG.warning("request %s of machine %s was written again while it was answered: the new one is "
                        "answered instead", request.name, machine)
            return None
        return answer()

    def _delivered(self, machine: str, name: str, stem: str, words: str) -> Delivered:
        """The program the request asks for (deliver); a request whose stem breaks the rule is
        refused, recorded and said in the log, never delivered (its name is the control's mistake)."""
        client = as_ascii(f"{machine}/{name}")
        why = bad_stem(stem)
        if why is None:
            return deliver(self.conn, machine, words, via="folder", client=client, config=self.config)
        reason = BAD_STEM.format(name=as_ascii(name)[:80], why=why)
        record_refusal(self.conn, machine, "folder", client, words, reason)
        LOG.warning("machine %s: %s", machine, reason)
        raise EngineError(reason)

    def close(self) -> None:
        self.conn.close()


def bad_stem(stem: str) -> str | None:
    """Why a request's stem breaks the rule (STEM), or None."""
    if STEM.fullmatch(stem):
        return None
    if len(stem) > 24:
        return f"has {len(stem)} characters"
    odd = next(character for character in stem if not STEM.fullmatch(character))
    return f"holds {as_ascii(repr(odd))}"


def _read_request(request: Path) -> bytes:
    """At most MAX_REQUEST_BYTES of the request, only if it is a regular file and no link
    (a link swapped in since it was listed would show another file's first line in the answer)."""
    try:
        descriptor = os.open(request, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return b""
    with open(descriptor, "rb") as file:
        return file.read(MAX_REQUEST_BYTES) if stat.S_ISREG(os.fstat(file.fileno()).st_mode) else b""


def _request_text(data: bytes) -> str:
    """The request's lines (of its first KiB), as ASCII, blank ones left out: what it asks for. A
    request is one line; deliver refuses more (an 840D's WRITE appends to a request file left
    unanswered), and anything else than a request's words, and records it."""
    lines = data[:MAX_REQUEST_BYTES].decode("ascii", "replace").splitlines()
    return "\n".join(line.strip() for line in lines if line.strip())


def _refused(folder: Path, machine: str, request: str, stem: str, reason: str, words: str) -> Answer:
    write_atomically(folder, f"{stem}{ERROR}", _answer_text(as_ascii(reason), words))
    return Answer(machine, request, refusal=reason)


def _sent(folder: Path, machine: str, request: str, stem: str, delivered: Delivered, words: str) -> Answer:
    """The program first, under a name carrying its bytes' hash; then the answer naming it."""
    name = program_file_name(delivered.program_id, delivered.data)
    write_atomically(folder, name, delivered.data)
    write_atomically(folder, f"{stem}{READY}", _answer_text(name, words))
    return Answer(machine, request, program_file=name)


def program_file_name(program_id: int, data: bytes) -> str:
    """The name the program's bytes are written under (PROGRAM_FILE): PG812_5BE02D1.MPF."""
    assert 0 < program_id < PROGRAM_ID_LIMIT, f"program id {program_id} would make a name of more than 24 characters"
    digest = hashlib.sha256(data).hexdigest()[:PROGRAM_FILE_HEX].upper()
    return PROGRAM_FILE.format(program_id=program_id, digest=digest)


def _answer_text(first: str, words: str) -> bytes:
    """An answer: its first line (the program file, or the refusal), then the request it answers, as
    read (one line; ASCII). The control compares the second line with what it wrote: an answer to
    its previous request, written in the milliseconds between its removing the old answer and its
    writing the new request, is then not taken for this one's (the race the adversary of issue 32
    left open)."""
    return f"{first}\n{as_ascii(one_line(words))}\n".encode("ascii")


def write_atomically(folder: Path, name: str, data: bytes) -> None:
    """`folder/name` holds `data` whole or is as it was: written under a temporary dot name, flushed,
    then renamed in one step, and the folder's entry flushed too."""
    temporary = folder / f".{name[:40]}.{uuid.uuid4().hex}.tmp"   # within NAME_MAX whatever the name
    descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
    try:
        with open(descriptor, "wb") as file:
            file.write(data)
            file.flush()
            os.fsync(file.fileno())
        os.replace(temporary, folder / name)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    _sync_folder(folder)


def _sync_folder(folder: Path) -> None:
    descriptor = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(descriptor)
    finally:
        os.close(descriptor)


class FolderService:
    """Request folders answered in a thread every `interval` seconds until close()."""

    def __init__(self, folder: RequestFolder, interval: float = POLL_SECONDS):
        self.folder, self.interval = folder, interval
        self._stop = threading.Event()
        self.thread = threading.Thread(target=self._run, name="engine-request-folder", daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while not self._stop.wait(self.interval):
            try:
                self.folder.poll_once()
            except Exception:   # a share gone for a moment, the database restarting: said, then tried again
                LOG.exception("request folders not answered")

    def close(self) -> None:
        self._stop.set()
        self.thread.join(timeout=30)
        self.folder.close()


def start_request_folder(root, machines: list[str], database_url: str, config: Config,
                         interval: float = POLL_SECONDS) -> FolderService:
    """The request folders of `machines` under `root`, answered in a thread of their own."""
    return FolderService(RequestFolder(root, machines, database_url, config), interval)
