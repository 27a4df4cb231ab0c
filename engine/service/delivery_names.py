"""What a control asks for, and the names it sees (issue 32; design notes §11).

A control fetches a file by name, so every program a machine may load has a name that (1) names
exactly one stored job, whatever the program inside is called, and (2) is legal on both controls
the engine serves: an 840D (`EXTCALL "GEAR42_J17.MPF"`: letters, digits and _, the first two
characters letters, at most 24 before the extension, which EXTCALL takes after a `.`) and a Fanuc
Data Server (file names of letters, digits, `_` and `.`). The name is the job's program name, then
`_J` and the job id, then `.MPF`: `GEAR42_J17.MPF`. The job id decides; the program name is there
for the operator, cut so the stem stays within 24 characters, and a name whose program part is not
that job's is refused (a stale list). Case is ignored, as both controls ignore it.

Besides a listed name a request may say, one line each (the request folder's words, engine.service.
request_folder): `JOB 17`, `GEAR 42` (that gear's newest stored job on the machine) and, for a
Fanuc's `M198 P1042`, `O1042` (the newest stored job on the machine whose O number is 1042)."""
from __future__ import annotations

import re
from typing import TYPE_CHECKING

import msgspec

from ..db.connection import scalar
from ..errors import EngineError

if TYPE_CHECKING:
    from ..db.connection import Connection

SUFFIX = ".MPF"
STEM_LENGTH = 24   # an 840D program name's limit, kept by the file names too
FILE_NAME = re.compile(r"(?P<program>[A-Z_][A-Z0-9_]*?)_J(?P<job>[0-9]{1,18})(?:\.MPF)?", re.IGNORECASE)
# (pattern, kind): the other words a request may use; rules as data
REQUEST_WORDS = (
    (re.compile(r"JOB\s+(?P<id>[0-9]{1,18})", re.IGNORECASE), "job"),
    (re.compile(r"GEAR\s+(?P<id>[0-9]{1,9})", re.IGNORECASE), "gear"),
    (re.compile(r"O0*(?P<id>[1-9][0-9]{0,7})", re.IGNORECASE), "o_number"),   # O1042, O0042: never O0
)
# The newest stored job of the machine for a gear, or for an O number (a Fanuc's M198 P<n>).
NEWEST_OF = {
    "gear": "SELECT max(id) FROM job WHERE machine = %s AND gear_id = %s",
    "o_number": "SELECT max(id) FROM job WHERE machine = %s AND params -> 'program_number' = to_jsonb(%s::integer)",
}
JOB = "SELECT machine, params ->> 'program_name', gear_id FROM job WHERE id = %s"


class Refused(EngineError):
    """A request the engine refuses: its one-line reason, and the job it named when that job is
    one of the machine's (kept with the request's record)."""

    def __init__(self, reason: str, job_id: int | None = None):
        super().__init__(reason)
        self.reason, self.job_id = reason, job_id


class Asked(msgspec.Struct, frozen=True):
    """A request understood: the job it names, and the program part of a file name (None for the
    request words)."""
    job_id: int
    program: str | None = None


def file_name(program_name: str | None, gear_id: int | None, job_id: int) -> str:
    """The name a machine sees for the job's program: GEAR42_J17.MPF (see the module's docstring)."""
    tail = f"_J{job_id}"
    program = (program_name or f"JOB_{gear_id}").upper()
    return f"{program[:STEM_LENGTH - len(tail)]}{tail}{SUFFIX}"


def asked(conn: Connection, machine: str, text: str) -> Asked:
    """The job a request names on `machine`, or Refused with the reason. A request of more than one
    line is refused, never answered by one of them: an 840D's WRITE appends, so a request file left
    unanswered and written again holds the old request first (the adversary of issue 32 had job 17's
    program answer a request for job 18)."""
    text = text.strip()
    lines = text.splitlines()
    if len(lines) > 1:
        raise Refused(f"the request holds {len(lines)} lines ({lines[0][:30]!r}, {lines[-1][:30]!r}): a request "
                      "is one line; delete the request file before writing a new one (WRITE appends to it)")
    found = FILE_NAME.fullmatch(text)
    if found:
        return Asked(int(found.group("job")), found.group("program").upper())
    for pattern, kind in REQUEST_WORDS:
        words = pattern.fullmatch(text)
        if words:
            return Asked(_job_of(conn, machine, kind, int(words.group("id"))))
    raise Refused(f"{text[:60]!r} names no program: ask for a listed name (GEAR42_J17.MPF), or JOB <id>, "
                  "GEAR <id> or O<number>")


def _job_of(conn: Connection, machine: str, kind: str, number: int) -> int:
    if kind == "job":
        return number
    found = scalar(conn.execute(NEWEST_OF[kind], (machine, number)))
    if found is None:
        what = f"gear {number}" if kind == "gear" else f"O number {number}"
        raise Refused(f"machine {machine} has no stored job of {what}; make one with `engine instantiate "
                      f"--gear ID --machine {machine}`")
    return found


def job_of_machine(conn: Connection, machine: str, request: Asked) -> tuple[int, str]:
    """The request's job and its file name, if the job is one of `machine`'s and the name's program
    part is its own; else Refused."""
    row = conn.execute(JOB, (request.job_id,)).fetchone()
    if row is None:
        raise Refused(f"job {request.job_id} does not exist; the machine's list shows what it may load")
    if row[0] != machine:   # the record names no job then: a machine's history holds only its own jobs
        raise Refused(f"job {request.job_id} is a job of machine {row[0]}, not of {machine}; it is not sent here")
    expected = file_name(row[1], row[2], request.job_id)
    if request.program is not None and expected.upper() != f"{request.program}_J{request.job_id}{SUFFIX}".upper():
        raise Refused(f"job {request.job_id}'s program is {expected}, not {request.program}: ask for the name "
                      "the list shows", request.job_id)
    return request.job_id, expected
