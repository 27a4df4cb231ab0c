"""`engine plot --job ID` for a hobbing job: the job's newest stored program drawn as the
simulation reads it (engine.hobbing.program_plot), so the picture shows what the machine will
do, not a second reading of the job's parameters."""
from __future__ import annotations

from ..errors import EngineError
from .program_plot import plot_stored_program

NEWEST_PROGRAM = "SELECT max(id) FROM program WHERE job_id = %s"


def plot_hobbing_job(conn, job_id: int, out) -> list[str]:
    """Draw the job's newest program to `out`; → one line per thing drawn."""
    program_id = newest_program(conn, job_id)
    return [f"program {program_id} (the job's newest)", *plot_stored_program(conn, program_id, out)]


def newest_program(conn, job_id: int) -> int:
    program_id = conn.execute(NEWEST_PROGRAM, (job_id,)).fetchone()[0]
    if program_id is None:
        raise EngineError(f"job {job_id} has no stored program to draw; make one with `engine instantiate --job {job_id}`")
    return program_id
