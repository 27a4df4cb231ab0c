"""The one path every program delivered to a control takes (issue 32; design notes §11): FTP
(engine.service.ftp), the request folder (engine.service.request_folder) and the web view all call
`deliver`, so what is proved at the exit is the same whichever way a program leaves.

A program reaches the machine only if it is right now. The job's newest stored program is sent
again only when it was made from the class's released version, with the job's parameters as they
are now (its input hash), is no draft, was read by a verifier, and renders again exactly and passes
the proof a new program gets (engine.programs.rendering: MATCH): so a control asking twice gets the
same program, the same lineage line. Anything else is made again exactly as `engine instantiate
--job J --out DIR/` makes it (engine.programs.remake.instantiate_job into a private folder, with the
config file's line endings), so every refusal of a file-writing `instantiate --job` applies
(unverified, an assumed blank, a draft-only class, the verifier's, the simulation's) and the bytes
sent are the bytes of that file. Every request, sent or refused, is then recorded in
program_request, in a transaction of its own after the program's."""
from __future__ import annotations

import os
import tempfile
from datetime import datetime
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import msgspec
import psycopg

from ..db.origin import MADE_HERE_SQL, refuse_elsewhere
from ..errors import EngineError
from ..names import LINE_BREAKING
from ..nc.layout import class_layout, nc_text
from ..programs.config import Config, line_ending
from .delivery_names import Refused, asked, file_name, job_of_machine

if TYPE_CHECKING:
    from ..db.connection import Connection

VIAS = ("ftp", "folder", "web")
MAX_ASKED, MAX_REASON = 200, 2000   # program_request's bounds
# The jobs a machine may load: its stored jobs whose class has a released version (no rendering),
# made here (a plant's jobs reach the head office as history: they are sent at their plant).
MACHINE_FILES = """
SELECT j.id, j.params ->> 'program_name', j.gear_id, j.gear_class, coalesce(max(p.created_at), j.created_at)
FROM job j LEFT JOIN program p ON p.job_id = j.id
WHERE j.machine = %s AND released_version(j.gear_class) IS NOT NULL AND """ + MADE_HERE_SQL.format(id="j.id") + """
GROUP BY j.id ORDER BY j.id"""
# The job's newest program, if it is one a control may be sent again unchanged (checked in SQL first,
# then rendered and proved).
REUSABLE = """
SELECT p.id, p.lines, p.gear_class, p.template_version, j.machine, m.kind, j.params
FROM program p JOIN job j ON j.id = p.job_id JOIN machine m ON m.name = j.machine
WHERE p.id = (SELECT max(id) FROM program WHERE job_id = %(job)s)
  AND p.gear_class = j.gear_class AND p.template_version = released_version(j.gear_class)
  AND NOT p.draft AND NOT p.unverified AND p.input_hash = job_input_hash(j.params, j.module_params)"""
RECORD = """
INSERT INTO program_request (machine, via, client, asked_for, job_id, program_id, refusal)
VALUES (%s, %s, %s, %s, %s, %s, %s)"""


class MachineFile(msgspec.Struct, frozen=True):
    """A program a machine may load, as its list shows it: the name it asks for, the job, and when
    the job last had a program stored (else when it was stored), for LIST and MDTM."""
    name: str
    job_id: int
    gear_id: int | None
    gear_class: str
    changed_at: datetime   # timestamptz


class Delivered(msgspec.Struct, frozen=True):
    """A program sent: the stored program, its job, the job's name in the machine's list and the
    bytes sent (the file `engine instantiate --job J --out DIR/` writes of that program)."""
    program_id: int
    job_id: int
    file_name: str
    data: bytes


def machine_files(conn: Connection, machine: str) -> list[MachineFile]:
    """The programs `machine` may load: its stored jobs of classes with a released version, by job
    id. Nothing is rendered (a control lists often); what is sent is proved when it is asked for."""
    with conn.transaction():   # left as it was found: idle, or in the caller's transaction
        rows = conn.execute(MACHINE_FILES, (machine,)).fetchall()
    return [MachineFile(file_name(name, gear, job), job, gear, gear_class, changed)
            for job, name, gear, gear_class, changed in rows]


def deliver(conn: Connection, machine: str, asked_for: str, *, via: str, client: str, config: Config) -> Delivered:
    """The program `asked_for` names, proved for `machine` now, and the request recorded; Refused
    (an EngineError, one line) otherwise, recorded too, the connection left usable. `conn` must not
    be inside a transaction: the program and the record are each committed here."""
    if via not in VIAS:
        raise ValueError(f"via {via!r} is not one of {VIAS}")
    if conn.info.transaction_status != psycopg.pq.TransactionStatus.IDLE:   # a caller's bug, not a refusal
        raise ValueError("deliver commits the program and its record itself: call it outside a transaction")
    job_id: int | None = None
    try:
        with conn.transaction():
            job_id, name = job_of_machine(conn, machine, asked(conn, machine, asked_for))
            refuse_elsewhere(conn, "job", job_id, "make and send it")
        program_id, data = _reused(conn, job_id, config) or _remade(conn, job_id, config)
    except EngineError as refusal:
        _rolled_back(conn)
        reason = one_line(str(refusal))
        job_id = refusal.job_id if isinstance(refusal, Refused) else job_id
        _record(conn, machine, via, client, asked_for, job_id, None, reason)
        raise Refused(reason, job_id) from None
    _record(conn, machine, via, client, asked_for, job_id, program_id, None)
    return Delivered(program_id, job_id, name, data)


def _reused(conn: Connection, job_id: int, config: Config) -> tuple[int, bytes] | None:
    """The job's newest program if it may be sent again unchanged (see the module's docstring)."""
    from ..programs.class_jobs import BLANK_PARAMS
    from ..programs.rendering import stored_rendering

    with conn.transaction():
        row = conn.execute(REUSABLE, {"job": job_id}).fetchone()
        if row is None:
            return None
        program_id, lines, gear_class, version, machine, kind, params = row
        if kind == "lathe" and not all(key in params for key in BLANK_PARAMS) and not _modelled(conn, gear_class):
            return None   # an assumed blank: made again, which refuses the file
        if not stored_rendering(conn, program_id).matches:
            return None
        layout = class_layout(conn, gear_class, version).ending_from(line_ending(config, machine))
    return program_id, nc_text(list(lines), layout).encode("ascii")


def _modelled(conn: Connection, gear_class: str) -> bool:
    from ..gears.models import model_for_class
    from ..programs import all_models  # noqa: F401  (registers every model)

    return model_for_class(conn, gear_class) is not None


def _remade(conn: Connection, job_id: int, config: Config) -> tuple[int, bytes]:
    """The job made again as `engine instantiate --job J --out DIR/` makes it; the file's bytes.
    A refusal names the file without the private folder it would have been written to (a path
    of the service's computer, gone once refused: the adversary of issue 32 saw it on a control)."""
    from ..programs.options import Output
    from ..programs.outputs import line_endings
    from ..programs.remake import instantiate_job

    with tempfile.TemporaryDirectory(prefix="engine-delivery-") as folder, \
            line_endings(partial(line_ending, config)):
        try:
            program = instantiate_job(conn, job_id, output=Output(out=folder + os.sep))
        except EngineError as refusal:
            if folder not in str(refusal):
                raise
            raise EngineError(str(refusal).replace(folder + os.sep, "")) from None
        assert program.program_id is not None and program.path is not None   # stored and written
        return program.program_id, Path(program.path).read_bytes()


def record_refusal(conn: Connection, machine: str, via: str, client: str, asked_for: str, reason: str) -> None:
    """A request refused before it could name a job (a request file's name that breaks the rule),
    recorded as every refusal is."""
    _record(conn, machine, via, client, asked_for, None, None, one_line(reason))


def _record(conn: Connection, machine: str, via: str, client: str, asked_for: str, job_id: int | None,
            program_id: int | None, refusal: str | None) -> None:
    """One row of program_request, committed on its own (a request is history even when refused)."""
    with conn.transaction():
        conn.execute(RECORD, (machine, via, one_line(client)[:MAX_ASKED], one_line(asked_for)[:MAX_ASKED], job_id,
                              program_id, None if refusal is None else refusal[:MAX_REASON]))


def _rolled_back(conn: Connection) -> None:
    """The connection usable again after a refusal: whatever transaction the refusal left open ended."""
    if not conn.closed and conn.info.transaction_status != psycopg.pq.TransactionStatus.IDLE:
        conn.rollback()


def as_ascii(text: str) -> str:
    """The text as a control shows it: ASCII, the engine's … spelt ..., anything else a ?."""
    return text.replace("…", "...").encode("ascii", "replace").decode("ascii")


def one_line(text: str) -> str:
    """The text on one line (a refusal is one line; a client's words are shown, never obeyed)."""
    return " ".join(LINE_BREAKING.sub(" ", text).split()) or "-"
