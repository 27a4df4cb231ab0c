"""Drawing records (table drawing, issue 26) written by `engine import-dxf` and held against a
stored turning job before it is made again (`engine instantiate --job/--jobs`).

A runner may edit job.params in SQL: the cutting data (speeds, feeds, depths) stay editable, but
the finished part, the blank, the tool-change position, the materials and each THREAD
operation's pitch and crest and root lines are the drawing's (engine.simulation.turning.drawing
DRAWING_FACTS, THREAD_FACTS; a record with NULL threads, made before migration 0028 and named by
no job then, holds the job to no thread data). A job whose params disagree with its drawing
record on one of them is refused, one line naming the job, the parameter and both values; the
proof itself reads the record (engine.programs.turning_jobs), so an edit could not pass it anyway,
but the refusal says what to do instead of a simulation finding the runner cannot explain."""
from __future__ import annotations

import hashlib
import math
from pathlib import Path
from typing import TYPE_CHECKING

from psycopg.types.json import Jsonb

from ..db.connection import scalar
from ..errors import EngineError
from ..machines.turning_cutting import DEFAULT_TOOL_MATERIAL, DEFAULT_WORKPIECE_MATERIAL
from ..names import shown
from ..simulation.turning.drawing import DRAWING_FACTS, DrawingRecord, drawn_threads, job_drawing

if TYPE_CHECKING:
    from ..db.connection import Connection

INSERT_DRAWING = """
INSERT INTO drawing (file_name, sha256, units, profile, stock_diameter, stock_z_front, stock_z_back, tool_change_x,
                     tool_change_z, workpiece_material, tool_materials, threads)
VALUES (%s, %s, %s, %s, %s, %s, %s, %s, %s, %s, %s, %s)
RETURNING id"""
# A fact missing from the params or the record stands for its default (jobs stored before the
# materials were: engine.machines.turning_cutting.job_materials).
DEFAULTS = {"workpiece_material": DEFAULT_WORKPIECE_MATERIAL, "tool_material": DEFAULT_TOOL_MATERIAL}
RELATIVE_TOLERANCE = 1e-9   # JSON and double precision numbers read back as stored; only float noise allowed
AGAIN = ("the part, blank, tool-change position, materials and threads are the drawing's: import the drawing "
         "again with `engine import-dxf` (--material for another material); nothing stored")


def file_sha256(path: str | Path) -> str:
    """The sha256 of the drawing file's bytes, stored with its record."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def store_drawing(conn: Connection, file_name: str, sha256: str, params: dict, module_params: dict) -> int:
    """Insert the record of a drawing just read (its facts as the import put them in the new job's
    params); → its id, for job.drawing_id. Inside the import's transaction."""
    facts = [Jsonb(params["profile"]), *(params.get(name) for name in DRAWING_FACTS[1:])]
    return scalar(conn.execute(INSERT_DRAWING, (file_name, sha256, params.get("units"), *facts,
                                                Jsonb(tool_materials(module_params)),
                                                Jsonb(drawn_threads(module_params)))))


def tool_materials(module_params: dict) -> dict:
    """{"n": tool material} of each operation n (module_params prep:n.tool_material)."""
    return {str(name).partition(":")[2]: values["tool_material"] for name, values in module_params.items()
            if str(name).startswith("prep:") and isinstance(values, dict) and "tool_material" in values}


def turning_job_drawing(conn: Connection, job_id: int, params: dict, module_params: dict) -> DrawingRecord:
    """The stored turning job's drawing record, the job's params held to it: EngineError (one line,
    nothing stored) for a job without one or one whose params disagree with it."""
    record = job_drawing(conn, job_id)
    if record is None:
        raise EngineError(f"job {job_id} is a turning job without a drawing record (job.drawing_id): its program "
                          "cannot be proved against the drawing; import the drawing with `engine import-dxf`; "
                          "nothing stored")
    for where, stated, recorded in disagreements(record, params, module_params):
        raise EngineError(f"job {job_id}: {where} = {shown(stated)} is not {shown(recorded)}, the value of its "
                          f"drawing record {record.id} ({record.file_name}); {AGAIN}")
    return record


def disagreements(record: DrawingRecord, params: dict, module_params: dict):
    """(where, the job's value, the record's value) of each fact they state differently."""
    for name, recorded in record.facts.items():
        stated = params.get(name) if isinstance(params, dict) else None
        if name == "profile" and isinstance(stated, list) and isinstance(recorded, list):
            yield from _segments(stated, recorded)
        elif not _same(stated, recorded, DEFAULTS.get(name)):
            yield f"params.{name}", stated, recorded
    for name, values in (module_params or {}).items():
        if str(name).startswith("prep:") and isinstance(values, dict):
            stated, recorded = values.get("tool_material"), record.tool_material(str(name).partition(":")[2])
            if not _same(stated, recorded, DEFAULTS["tool_material"]):
                yield f"module_params.{name}.tool_material", stated, recorded
    if record.threads is not None:   # None: a record made before threads were recorded (migration 0028)
        yield from _threads(drawn_threads(module_params or {}), record.threads, module_params or {})


def _same(stated, recorded, default) -> bool:
    stated = default if stated is None else stated
    recorded = default if recorded is None else recorded
    numbers = (int, float)
    if isinstance(stated, numbers) and isinstance(recorded, numbers) and not isinstance(stated, bool) \
            and not isinstance(recorded, bool):
        return math.isclose(stated, recorded, rel_tol=RELATIVE_TOLERANCE, abs_tol=RELATIVE_TOLERANCE)
    return stated == recorded


def _threads(stated: dict, recorded: dict, module_params: dict):
    """Each THREAD operation's pitch and crest and root lines against the record's; an operation
    that is a THREAD in only one of them disagrees on its kind."""
    for n in sorted(set(stated) | set(recorded)):
        where = f"module_params.cutmotion:{n}"
        if n not in stated or n not in recorded:
            values = module_params.get(f"cutmotion:{n}")
            yield f"{where}.kind", values.get("kind") if isinstance(values, dict) else None, \
                "THREAD" if n in recorded else None
        elif not _same(stated[n]["thread_pitch"], recorded[n].get("thread_pitch"), None):
            yield f"{where}.thread_pitch", stated[n]["thread_pitch"], recorded[n].get("thread_pitch")
        elif not _same_lines(stated[n]["paths"], recorded[n].get("paths")):
            yield f"{where}.paths", stated[n]["paths"], recorded[n].get("paths")


def _same_lines(stated, recorded) -> bool:
    """The thread's paths (lists of segments) equal but for float noise."""
    if isinstance(stated, list) and isinstance(recorded, list):
        return len(stated) == len(recorded) and all(_same_lines(a, b) for a, b in zip(stated, recorded, strict=True))
    return _same(stated, recorded, None)


def _segments(stated: list, recorded: list):
    """The first segment of the profile that differs (by its index), or the segment counts."""
    if len(stated) != len(recorded):
        yield "the number of segments of params.profile", len(stated), len(recorded)
    for index, (mine, theirs) in enumerate(zip(stated, recorded, strict=False)):
        if not (isinstance(mine, list) and isinstance(theirs, list) and len(mine) == len(theirs)
                and all(_same(a, b, None) for a, b in zip(mine, theirs, strict=True))):
            yield f"params.profile[{index}]", mine, theirs
            return
