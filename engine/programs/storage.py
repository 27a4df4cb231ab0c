"""Storing jobs and programs: one at a time, or a batch through COPY. Files are not written
here: engine.programs.outputs writes them after the COMMIT of the caller's files_after_commit.

Programs are records (design notes §10): no role may write the program table. The engine stores
them through the database's own path, which checks each program against its job and the stored
template version and records who stored it: store_program for one, COPY into the view
program_submission for a batch (migration 0010). A program is stored only with a safe name
(engine/names.py) and lines that are one NC line each: a line break inside a line would be a
block that no check read. The database refuses both too (migrations 0009, 0010); here they are
refused with a message that names the program."""
from __future__ import annotations

from dataclasses import dataclass

from psycopg.types.json import Jsonb

from ..errors import EngineError
from ..names import checked, line_breaking, shown
from .records import Encoded, Planned, Program

INSERT_JOB = """
INSERT INTO job (gear_id, gear_class, machine, hob_id, params, module_params, cutting)
VALUES (%s, %s, %s, %s, %s, %s, %s) RETURNING id"""
INSERT_PROGRAM = "SELECT store_program(%s, %s, %s, %s, %s, %s, %s, %s)"
COPY_JOB = "COPY job (id, gear_id, gear_class, machine, hob_id, params, module_params, cutting) FROM STDIN"
COPY_PROGRAM = ("COPY program_submission (id, job_id, gear_class, template_version, template_hash, name, lines, "
                "row_ids, trace) FROM STDIN (FORMAT BINARY)")
PROGRAM_TYPES = ("int8", "int8", "text", "int4", "text", "text", "text[]", "int4[]", "jsonb")


def store_one(conn, planned: Planned, existing_job: int | None, path: str | None) -> Program:
    refuse_unsafe(planned.name, planned.lines)
    job_id = existing_job
    if job_id is None:
        job_id = conn.execute(INSERT_JOB, (planned.gear_id, planned.gear_class, planned.machine, planned.hob_id,
                                           Jsonb(planned.params), Jsonb(planned.module_params),
                                           Jsonb(planned.cutting or {}))).fetchone()[0]
    program_id = conn.execute(INSERT_PROGRAM, _program_values(job_id, planned)).fetchone()[0]
    return _program(program_id, job_id, planned, path)


def store_many(conn, encoded: list[Encoded], out=None) -> "Batch":
    """All jobs and programs in one transaction, through COPY (the batch path); `out` is where
    the caller writes their files."""
    for item in encoded:
        refuse_unsafe(item.name, item.lines)
    with conn.transaction():
        job_ids = _next_ids(conn, "job_id_seq", len(encoded))
        program_ids = _next_ids(conn, "program_id_seq", len(encoded))
        with conn.cursor().copy(COPY_JOB) as copy:
            for job_id, item in zip(job_ids, encoded):
                copy.write_row((job_id, item.gear_id, item.gear_class, item.machine, item.hob_id,
                                _json(item.params), _json(item.module_params), _json(item.cutting)))
        _copy_programs(conn, program_ids, job_ids, encoded)
    return Batch(len(encoded), sum(len(item.lines) for item in encoded),
                 min(program_ids), max(program_ids), out,
                 tuple(f"{item.name}: {note}" for item in encoded for note in item.notes))


def store_programs(conn, encoded: list[Encoded], job_ids: list[int], out=None) -> "Batch":
    """Programs of stored jobs (made again), in one transaction through COPY."""
    for item in encoded:
        refuse_unsafe(item.name, item.lines)
    with conn.transaction():
        program_ids = _next_ids(conn, "program_id_seq", len(encoded))
        _copy_programs(conn, program_ids, job_ids, encoded)
    return Batch(len(encoded), sum(len(item.lines) for item in encoded), min(program_ids), max(program_ids), out,
                 tuple(f"{item.name}: {note}" for item in encoded for note in item.notes))


def refuse_unsafe(name: str, lines: list[str]) -> None:
    """EngineError unless the program's name is an 840D program name and no line breaks."""
    checked("program", name, "program name", "set job.params.program_name in SQL; nothing stored")
    if line_breaking("".join(lines)) is None:
        return
    for number, line in enumerate(lines, 1):
        found = line_breaking(line)
        if found is not None:
            raise EngineError(f"program {name} line {number} {shown(line)} holds {shown(found)}, which would start "
                              "another NC block: nothing stored; the job parameter or template row that made it "
                              "must not hold line breaks")


def _copy_programs(conn, program_ids: list[int], job_ids: list[int], encoded: list[Encoded]) -> None:
    with conn.cursor().copy(COPY_PROGRAM) as copy:
        copy.set_types(PROGRAM_TYPES)
        for program_id, job_id, item in zip(program_ids, job_ids, encoded):
            copy.write_row((program_id, job_id, item.gear_class, item.template_version, item.template_hash,
                            item.name, item.lines, item.row_ids, _json(item.trace)))


def _json(text: str) -> Jsonb:
    """JSON encoded already (by a batch worker): passed on as it is."""
    return Jsonb(text, dumps=_as_is)


def _as_is(text: str) -> str:
    return text


@dataclass(frozen=True)
class Batch:
    """What a batch stored: how many programs and lines, the lowest and highest program id
    (other sessions may draw ids in between), and where files went."""
    programs: int
    lines: int
    first_program_id: int
    last_program_id: int
    path: str | None
    notes: tuple = ()   # "<program name>: <note>", one line each

    def __len__(self) -> int:
        return self.programs


def _next_ids(conn, sequence: str, count: int) -> list[int]:
    rows = conn.execute("SELECT nextval(%s::regclass) FROM generate_series(1, %s)", (sequence, count))
    return [row[0] for row in rows]


def _program_values(job_id: int, planned) -> tuple:
    template = planned.template
    return (job_id, planned.gear_class, template.version, template.hash, planned.name,
            planned.result.lines, planned.result.row_ids, Jsonb(planned.result.trace))


def _program(program_id: int, job_id: int, planned: Planned, path) -> Program:
    return Program(program_id, job_id, planned.name, planned.result.lines, planned.gear_class,
                   planned.template.version, planned.template.hash, path, planned.result.trace,
                   planned.result.row_ids, tuple(planned.notes))
