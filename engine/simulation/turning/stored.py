"""A stored lathe program simulated against the records of its job (`engine simulate --program
ID`): its lines, the job's drawing record (the part, blank, tool-change position and materials,
engine.simulation.turning.drawing), the job's operations and cutting data (module_params) and the
machine as the database holds them now. A class job's program (no drawing record, no profile, no
operations: `engine instantiate --class`) is simulated against the blank its params state, or
the one it implies, and the report says what was not checked (engine.simulation.turning.undrawn)."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ...errors import EngineError
from ...machines.records import Machine
from . import BLANK_PARAMS
from .drawing import job_drawing, proof_params
from .report import TurningReport
from .run import simulate_turning

if TYPE_CHECKING:
    from ...db.connection import Connection

JOB_QUERY = """
SELECT j.id, j.params, j.module_params
FROM program p JOIN job j ON j.id = p.job_id
WHERE p.id = %s"""


def simulate_stored_turning(conn: Connection, program_id: int, name: str, lines: list[str],
                            machine: Machine) -> TurningReport:
    row = conn.execute(JOB_QUERY, (program_id,)).fetchone()
    job_id, params, module_params = row if row is not None else (None, None, None)
    record = job_drawing(conn, job_id) if job_id is not None else None
    if record is None and isinstance(params, dict) and "profile" not in params and not module_params:
        blank = {name: params[name] for name in BLANK_PARAMS if name in params}
        return simulate_turning(lines, blank, {}, machine, name)
    if record is None or not isinstance(params, dict):
        raise EngineError(f"program {program_id} is a lathe program without a drawing (its job has no drawing "
                          "record): the simulation has no part to follow it against")
    params, module_params = proof_params(record, params, module_params or {})
    return simulate_turning(lines, params, module_params, machine, name)
