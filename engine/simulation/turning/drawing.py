"""A turning job's drawing record (table drawing, issue 26): the finished part, the blank, the
tool-change position and the materials as `engine import-dxf` read them from the drawing,
written once and never changed. The proof takes these facts from the record, not from the job's
params, which a runner may edit in SQL (design notes §8, "the drawing record"): `proof_params`
lays them over the job's parameters, so the cutting data (speeds, feeds, depths) stay the job's. A THREAD
operation's pitch and crest and root lines are the drawing's too (drawing.threads)."""
from __future__ import annotations

import copy
from typing import TYPE_CHECKING

import msgspec

if TYPE_CHECKING:
    from ...db.connection import Connection

# The job parameters a drawing record holds, each under the same name as its column.
DRAWING_FACTS = ("profile", "stock_diameter", "stock_z_front", "stock_z_back", "tool_change_x", "tool_change_z",
                 "workpiece_material")

# A THREAD operation's drawn data (module_params cutmotion:n), recorded in drawing.threads (migration
# 0028): the pitch of the drawing's @P and the crest and root lines (design notes §8).
THREAD_FACTS = ("thread_pitch", "paths")

DRAWING_OF_JOB = """
SELECT d.id, d.file_name, d.tool_materials, d.threads, d.profile, d.stock_diameter, d.stock_z_front, d.stock_z_back,
       d.tool_change_x, d.tool_change_z, d.workpiece_material
FROM job j JOIN drawing d ON d.id = j.drawing_id
WHERE j.id = %s"""


class DrawingRecord(msgspec.Struct, frozen=True):
    id: int
    file_name: str
    facts: dict                       # DRAWING_FACTS name → value; None: not recorded (the default or assumed)
    tool_materials: dict | None       # {"n": material} per operation n; None: not recorded (the default)

    def tool_material(self, operation: str):
        return (self.tool_materials or {}).get(operation)

    # {"n": {"thread_pitch": p, "paths": [...]}} per THREAD operation n; {} none; None: not recorded
    threads: dict | None = None


def job_drawing(conn: Connection, job_id: int) -> DrawingRecord | None:
    """The drawing record of the stored job, or None for a job without one."""
    row = conn.execute(DRAWING_OF_JOB, (job_id,)).fetchone()
    if row is None:
        return None
    drawing_id, file_name, tool_materials, threads, *facts = row
    return DrawingRecord(drawing_id, file_name, dict(zip(DRAWING_FACTS, facts, strict=True)), tool_materials,
                         threads)


def drawn_threads(module_params: dict) -> dict:
    """{"n": {"thread_pitch": p, "paths": [...]}} of each THREAD operation n in module_params."""
    return {str(name).partition(":")[2]: {fact: values.get(fact) for fact in THREAD_FACTS}
            for name, values in module_params.items()
            if str(name).startswith("cutmotion:") and isinstance(values, dict) and values.get("kind") == "THREAD"}


def proof_params(record: DrawingRecord, params: dict, module_params: dict) -> tuple[dict, dict]:
    """Copies of the job's (params, module_params) with the record's facts in place of theirs:
    what the simulation proves the program against. A fact the record leaves NULL is removed, so
    the simulation takes its default (the assumed blank, the default materials) as at import."""
    params = {**params}
    for name, value in record.facts.items():
        _put(params, name, value)
    module_params = copy.deepcopy(module_params)
    for name, values in module_params.items():
        if str(name).startswith("prep:") and isinstance(values, dict):
            _put(values, "tool_material", record.tool_material(str(name).partition(":")[2]))
    for n, thread in (record.threads or {}).items():   # None: not recorded, the job's as before
        values = module_params.get(f"cutmotion:{n}")
        if isinstance(values, dict):
            values.update(thread)
    return params, module_params


def _put(values: dict, name: str, value) -> None:
    if value is None:
        values.pop(name, None)
    else:
        values[name] = value
