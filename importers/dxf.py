"""`engine import-dxf`: a lathe drawing becomes one turning job (design notes §3, §8).

The drawing is read, its numbers become job parameters, the program is computed and
checked against the lathe (so a job that could never be instantiated is not stored), and
the job is stored with its drawing record (the part, blank, tool-change position, materials and
thread pitch and lines as read, with the file's sha256; engine.programs.drawing_records), all in
one transaction: on any error nothing is stored. The program itself is stored by
`engine instantiate --job ID`, like every instantiation.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from psycopg.types.json import Jsonb

from engine.db.connection import scalar
from engine.drawings.drawing import read_drawing
from engine.memory import no_cycle_collection
from engine.names import checked
from engine.programs.drawing_records import file_sha256, store_drawing
from engine.programs.turning_jobs import lathe, plan_turning_job, turning_class
from engine.turning.job_params import ProfileOptions, turning_job
from engine.turning.model import ISO_PROGRAM_NUMBERS, job_passes, key, present_operations

if TYPE_CHECKING:
    from engine.db.connection import Connection

INSERT_TURNING_JOB = """
INSERT INTO job (id, gear_id, gear_class, machine, hob_id, params, module_params, drawing_id)
VALUES (%s, NULL, %s, %s, NULL, %s, %s, %s)"""


@dataclass
class ImportReport:
    job_id: int
    drawing: str
    machine: str
    gear_class: str
    program_lines: int   # as `engine instantiate --job` stores the program: the engine's lineage line counted
    operations: list[dict] = field(default_factory=list)
    repairs: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def import_dxf(conn: Connection, path: str | Path, machine_name: str | None = None,
               options: ProfileOptions = ProfileOptions(), alternate: list[int] | None = None,
               program_name: str | None = None, draft: bool = False, profile_layer: str | None = None,
               materials: tuple[str | None, str | None] = (None, None)) -> ImportReport:
    """Read the drawing and store its job; EngineError (nothing stored) if it cannot become one.
    The program is named `program_name`, else after the drawing's file name (job_params.drawing_names);
    the profile is read from layer `profile_layer` (None: layer 0, or the layer read_drawing chooses);
    `materials`: (tool material, workpiece material) for the cutting-data table, None = default."""
    # said before the drawing's own problems
    checked("drawing", Path(path).name, "drawing file name", "rename the file")
    if program_name is not None:
        checked("program", program_name, "--program-name")
    machine = lathe(conn, machine_name)
    gear_class = turning_class(machine)
    with no_cycle_collection():   # a large drawing: the profile, its parameters and passes
        return _import(conn, (path, profile_layer), machine, gear_class, options, (alternate, program_name, materials),
                       draft)


def _import(conn: Connection, source: tuple, machine, gear_class: str, options: ProfileOptions, choices: tuple,
            draft: bool) -> ImportReport:
    alternate, program_name, materials = choices
    drawing = read_drawing(*source)   # (path, profile layer)
    sha256 = file_sha256(source[0])   # of the bytes just read: stored with the drawing record
    with conn.transaction():
        job_id = scalar(conn.execute("SELECT nextval('job_id_seq')"))
        program_number = (job_id - 1) % ISO_PROGRAM_NUMBERS + 1    # the job id, wrapped into O0001 … O8999
        job = turning_job(drawing, machine.name, gear_class, program_number, options, alternate, program_name,
                          materials)
        passes = job_passes(job.params, job.module_params)
        planned = plan_turning_job(conn, gear_class, machine, job.params, job.module_params, passes, draft)
        drawing_id = store_drawing(conn, Path(source[0]).name, sha256, job.params, job.module_params)
        conn.execute(INSERT_TURNING_JOB, (job_id, gear_class, machine.name, Jsonb(job.params),
                                          Jsonb(job.module_params), drawing_id))
    notes = job.notes + empty_operations(job, passes) + drawing.notes
    return ImportReport(job_id, str(drawing.source), machine.name, gear_class, len(planned.result.lines) + 1,
                        job.operations, drawing.repairs, notes)


def empty_operations(job, passes: dict) -> list[str]:
    return [f"operation {n} ({job.module_params[key('cutmotion', n)]['kind']}) has no pass: nothing to cut "
            "(the blank lies within the allowance of the profile); the program leaves it out"
            for n in present_operations(job.module_params) if n in passes and not passes[n]]
