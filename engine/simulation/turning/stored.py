"""A stored lathe program simulated against the records of its job (`engine simulate --program
ID`): its lines, the job's params and module_params and the machine as the database holds them now."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ...errors import EngineError
from ...machines.records import Machine
from .report import TurningReport
from .run import simulate_turning

if TYPE_CHECKING:
    from ...db.connection import Connection

JOB_QUERY = """
SELECT j.params, j.module_params
FROM program p JOIN job j ON j.id = p.job_id
WHERE p.id = %s"""


def simulate_stored_turning(conn: Connection, program_id: int, name: str, lines: list[str],
                            machine: Machine) -> TurningReport:
    row = conn.execute(JOB_QUERY, (program_id,)).fetchone()
    params, module_params = row if row is not None else (None, None)
    if not isinstance(params, dict) or "profile" not in params:
        raise EngineError(f"program {program_id} is a lathe program without a drawing (its job has no "
                          "params.profile): the simulation has no part to follow it against")
    return simulate_turning(lines, params, module_params or {}, machine, name)
