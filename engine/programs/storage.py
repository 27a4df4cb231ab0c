"""Storing jobs and programs: one at a time, or a batch through COPY. Files are not written
here: engine.programs.outputs writes them after the COMMIT of the caller's files_after_commit.

Programs are records (design notes §10): no role may write the program table. The engine stores
them through the database's own path, which checks each program against its job and the stored
template version and records who stored it: the view program_submission, one INSERT or a
batch through COPY (check_program, schema/schema.sql). Each program gets its lineage line here (engine.programs.
lineage), checked by the database too (check_program_release). A program is stored only with a safe name
(engine/names.py) and lines that are one NC line each: a line break inside a line would be a
block that no check read. The database refuses both too (program_safe_name, check_program); here they are
refused with a message that names the program."""
from __future__ import annotations

import contextlib
import re
from typing import TYPE_CHECKING

import msgspec
from psycopg.errors import ForeignKeyViolation
from psycopg.types.json import Jsonb

from ..db.connection import scalar
from ..errors import EngineError
from ..names import checked, line_breaking, shown
from ..nc.lineage import lineage_line, lineage_words, refuse_lineage_shaped, with_lineage
from ..notes import prefixed
from .records import Encoded, Planned, Program

if TYPE_CHECKING:
    from ..db.connection import Connection

# What a lineage line needs from the database: the hash of each job's stored parameters, each
# machine's dialect (its comment form), whether each template version is a draft (not released).
INPUT_HASHES = "SELECT id, job_input_hash(params, module_params) FROM job WHERE id = ANY(%s)"
DIALECTS = "SELECT name, dialect FROM machine WHERE name = ANY(%s)"
DRAFTS = ("SELECT c, v, NOT EXISTS (SELECT 1 FROM template_release r WHERE r.gear_class = c AND r.version = v) "
          "FROM unnest(%s::text[], %s::int[]) AS x (c, v)")

INSERT_JOB = """
INSERT INTO job (gear_id, gear_class, machine, hob_id, params, module_params, cutting, work_holding_id)
VALUES (%s, %s, %s, %s, %s, %s, %s, %s) RETURNING id"""
INSERT_PROGRAM = ("INSERT INTO program_submission (id, job_id, gear_class, template_version, template_hash, name, "
                  "lines, row_ids, trace, unverified) VALUES (%s, %s, %s, %s, %s, %s, %s, %s, %s, %s) RETURNING id")
COPY_JOB = ("COPY job (id, gear_id, gear_class, machine, hob_id, params, module_params, cutting, work_holding_id) "
            "FROM STDIN")
COPY_PROGRAM = ("COPY program_submission (id, job_id, gear_class, template_version, template_hash, name, lines, "
                "row_ids, trace) FROM STDIN (FORMAT BINARY)")
PROGRAM_TYPES = ("int8", "int8", "text", "int4", "text", "text", "text[]", "int4[]", "jsonb")


# Why a lathe class job on an assumed blank never reaches a file: the blank the simulation proves it
# against comes from the program's own cuts, so a rapid through bar the program never cuts (the
# adversary's rapid to the axis 50 mm behind the face, a groove's run-in along the bar) cannot be
# seen, and a bound value moved at instantiate moves the blank with it.
ASSUMED_BLANK_FILE = ("is a lathe class job proved against a blank assumed from its own cuts, which cannot show a "
                      "rapid through bar the program never cuts; it is never written to a file ({path}): state the "
                      "bar with the params stock_diameter, stock_z_front and stock_z_back (mm, the program's frame) "
                      "and instantiate again; nothing stored")


def refuse_assumed_blank_file(name: str, assumed_blank: bool, path) -> None:
    if assumed_blank and path is not None:
        raise EngineError(f"program {name} " + ASSUMED_BLANK_FILE.format(path=path))


def store_one(conn: Connection, planned: Planned, existing_job: int | None, path: str | None) -> Program:
    """The program (and its job, unless `existing_job`), its lineage line added. An unverified
    program (engine.programs.class_jobs) is stored only without a file for the machine."""
    refuse_unsafe(planned.name, planned.lines)
    if planned.unverified and path is not None:
        raise EngineError(f"program {planned.name} is unverified: it is never written to a file ({path}); "
                          "nothing stored")
    refuse_assumed_blank_file(planned.name, planned.assumed_blank, path)
    with deleted_meanwhile(conn, gears=[planned.gear_id], hobs=[planned.hob_id], jobs=[existing_job]), \
            conn.transaction():
        return _stored_one(conn, planned, existing_job, path)


def _stored_one(conn: Connection, planned: Planned, existing_job: int | None, path: str | None) -> Program:
    job_id = existing_job
    if job_id is None:
        job_id = scalar(conn.execute(INSERT_JOB, (planned.gear_id, planned.gear_class, planned.machine,
                                                  planned.hob_id, Jsonb(planned.params), Jsonb(planned.module_params),
                                                  Jsonb(planned.cutting or {}), planned.work_holding_id)))
    program_id = _next_ids(conn, "program_id_seq", 1)[0]
    template = planned.template
    lines, row_ids = Lineage(conn, [planned.machine], [(template.gear_class, template.version)], [job_id]).added(
        program_id, job_id, planned.machine, template.gear_class, template.version, template.hash,
        planned.result.lines, planned.result.row_ids, planned.unverified)
    conn.execute(INSERT_PROGRAM, (program_id, job_id, planned.gear_class, template.version, template.hash,
                                  planned.name, lines, row_ids, Jsonb(planned.result.trace), planned.unverified))
    return _program(program_id, job_id, planned, path, lines, row_ids)


class Lineage:
    """Lineage lines for the programs of one store: what they need read in three queries."""

    def __init__(self, conn: Connection, machines, versions, job_ids, input_hashes: dict | None = None):
        self.input_hashes = dict(conn.execute(INPUT_HASHES, (list(job_ids),)).fetchall()) | (input_hashes or {})
        self.dialects: dict[str, str] = dict(conn.execute(DIALECTS, (list(set(machines)),)).fetchall())
        classes, numbers = zip(*set(versions)) if versions else ((), ())
        self.drafts = {(c, v): draft for c, v, draft in conn.execute(DRAFTS, (list(classes), list(numbers)))}

    def added(self, program_id, job_id, machine, gear_class, version, template_hash, lines, row_ids,
              unverified: bool = False):
        words = lineage_words(program_id, gear_class, version, template_hash, self.input_hashes[job_id],
                              self.drafts[(gear_class, version)], unverified)
        return with_lineage(list(lines), list(row_ids), lineage_line(words, self.dialects.get(machine, "")))


def store_many(conn: Connection, encoded: list[Encoded], out=None, files=None) -> Batch:
    """All jobs and programs in one transaction, through COPY (the batch path); `out` is where
    the caller writes their files."""
    stored = store_slice(conn, encoded)
    _stored_texts(files, stored.texts)
    return stored_batch(encoded, stored.program_ids, out)


class StoredSlice(msgspec.Struct, frozen=True):
    """What one COPY of a batch stored: the program ids in order, {program name: lines as stored}."""
    program_ids: list[int]
    texts: dict


def store_slice(conn: Connection, encoded: list[Encoded]) -> StoredSlice:
    """New jobs and their programs through COPY, in a transaction (a savepoint inside the batch's
    own: a batch planned in workers stores each slice as it comes back, issue 28)."""
    for item in encoded:
        refuse_unsafe(item.name, item.lines)
    with deleted_meanwhile(conn, gears=[item.gear_id for item in encoded], hobs=[item.hob_id for item in encoded]), \
            conn.transaction():
        job_ids = _next_ids(conn, "job_id_seq", len(encoded))
        program_ids = _next_ids(conn, "program_id_seq", len(encoded))
        with conn.cursor().copy(COPY_JOB) as copy:
            for job_id, item in zip(job_ids, encoded):
                copy.write_row((job_id, item.gear_id, item.gear_class, item.machine, item.hob_id,
                                _json(item.params), _json(item.module_params), _json(item.cutting),
                                item.work_holding_id))
        return StoredSlice(program_ids, _copy_programs(conn, program_ids, job_ids, encoded))


def stored_batch(encoded: list[Encoded], program_ids: list[int], out) -> Batch:
    """The report of a batch stored: programs, lines (each with its lineage line), ids, notes."""
    return Batch(len(encoded), sum(len(item.lines) + 1 for item in encoded),
                 min(program_ids), max(program_ids), out,
                 tuple(prefixed(f"{item.name}: ", note) for item in encoded for note in item.notes))


def store_programs(conn: Connection, encoded: list[Encoded], job_ids: list[int], out=None, files=None) -> Batch:
    """Programs of stored jobs (made again), in one transaction through COPY."""
    for item in encoded:
        refuse_unsafe(item.name, item.lines)
    with deleted_meanwhile(conn, jobs=job_ids), conn.transaction():
        program_ids = _next_ids(conn, "program_id_seq", len(encoded))
        _stored_texts(files, _copy_programs(conn, program_ids, job_ids, encoded))
    return stored_batch(encoded, program_ids, out)


# The gears, hobs and jobs of a store that are no longer in the database.
GONE = """SELECT 'gear', g::text FROM unnest(%s::bigint[]) AS g WHERE NOT EXISTS (SELECT 1 FROM gear WHERE id = g)
UNION ALL SELECT 'hob', h FROM unnest(%s::text[]) AS h WHERE NOT EXISTS (SELECT 1 FROM hob WHERE id = h)
UNION ALL SELECT 'job', j::text FROM unnest(%s::bigint[]) AS j WHERE NOT EXISTS (SELECT 1 FROM job WHERE id = j)"""


@contextlib.contextmanager
def deleted_meanwhile(conn: Connection, gears=(), hobs=(), jobs=()):
    """A gear, hob or job deleted by another session while its program was made is said as such:
    the store refused by its foreign key (rolled back, the block being a transaction or savepoint)
    names what is gone. Another foreign key's refusal is left as it is (a bug)."""
    try:
        yield
    except ForeignKeyViolation as error:
        gone = conn.execute(GONE, tuple(sorted({i for i in ids if i is not None}) for ids in (gears, hobs, jobs)))
        named = [f"{kind} {name}" for kind, name in gone]
        if not named:
            raise
        raise EngineError(_deleted_message(named)) from error


def _deleted_message(named: list[str]) -> str:
    if len(named) == 1:
        return f"{named[0]} was deleted while its program was made; nothing stored"
    return f"{', '.join(named)} were deleted while their programs were made; nothing stored"


# The characters check_program (schema/schema.sql) refuses in a stored line: every control
# character, the TAB included (a line is one block of words separated by spaces).
CONTROL = re.compile("[\x01-\x1f\x7f-\x9f\u2028\u2029]")


def refuse_unsafe(name: str, lines: list[str]) -> None:
    """EngineError unless the program's name is an 840D program name and no line breaks."""
    checked("program", name, "program name", "set job.params.program_name in SQL; nothing stored")
    refuse_lineage_shaped(name, lines)
    if CONTROL.search("".join(lines)) is None:
        return
    for number, line in enumerate(lines, 1):
        found = line_breaking(line)
        if found is not None:
            raise EngineError(f"program {name} line {number} {shown(line)} holds {shown(found)}, which would start "
                              "another NC block: nothing stored; the job parameter or template row that made it "
                              "must not hold line breaks")
        control = CONTROL.search(line)
        if control is not None:
            raise EngineError(f"program {name} line {number} {shown(line)} holds {shown(control.group())}: a stored "
                              "NC line holds no control character; write spaces in the template row (or the "
                              "imported program) that made it; nothing stored")


def _copy_programs(conn: Connection, program_ids: list[int], job_ids: list[int], encoded: list[Encoded]) -> dict:
    """COPY the programs with their lineage lines; {program name: lines as stored}."""
    lineage = Lineage(conn, [item.machine for item in encoded],
                      [(item.gear_class, item.template_version) for item in encoded], job_ids)
    stored = {}
    with conn.cursor().copy(COPY_PROGRAM) as copy:
        copy.set_types(PROGRAM_TYPES)
        for program_id, job_id, item in zip(program_ids, job_ids, encoded):
            lines, row_ids = lineage.added(program_id, job_id, item.machine, item.gear_class, item.template_version,
                                           item.template_hash, item.lines, item.row_ids)
            copy.write_row((program_id, job_id, item.gear_class, item.template_version, item.template_hash,
                            item.name, lines, row_ids, _json(item.trace)))
            stored[item.name] = lines
    return stored


def _json(text: str | None) -> Jsonb:
    """JSON encoded already (by a batch worker): passed on as it is."""
    return Jsonb(text, dumps=_as_is)


def _as_is(text: str) -> str:
    return text


class Batch(msgspec.Struct, frozen=True):
    """What a batch stored (or, a dry run, would store): how many programs and lines, the lowest
    and highest program id (other sessions may draw ids in between; None in a dry run), where
    files went, and the gears or jobs skipped as bad (--skip-bad), each with its reason."""
    programs: int
    lines: int
    first_program_id: int | None
    last_program_id: int | None
    path: str | None
    notes: tuple = ()     # "<program name>: <note>", one line each
    skipped: tuple = ()   # "gear 7: <reason>" (or "job 7: …"), one line each
    dry_run: bool = False

    def __len__(self) -> int:
        return self.programs


def _next_ids(conn: Connection, sequence: str, count: int) -> list[int]:
    rows = conn.execute("SELECT nextval(%s::regclass) FROM generate_series(1, %s)", (sequence, count))
    return [row[0] for row in rows]


def _stored_texts(files, stored: dict) -> None:
    """The files of the batch hold the programs as stored, lineage line and all."""
    if files is not None:
        files.replace_texts(stored)


def _program(program_id: int, job_id: int, planned: Planned, path, lines, row_ids) -> Program:
    return Program(program_id, job_id, planned.name, lines, planned.gear_class,
                   planned.template.version, planned.template.hash, path, planned.result.trace,
                   row_ids, tuple(planned.notes), planned.layout, planned.unverified)
