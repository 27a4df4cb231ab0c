"""`engine plot --job ID` for a hobbing job: a stored program of the job drawn as the simulation
reads it (engine.hobbing.program_plot), so the picture shows what the machine will do, not a
second reading of the job's parameters. The program is the newest one made from a released
template version, the one that reaches the machine: an editor's draft tried on the job
(`instantiate --job ID --draft`, program.draft) never does. Only when the job has
nothing but drafts is the newest draft drawn, and the picture and the report say draft."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..errors import EngineError
from .program_plot import plot_stored_program

if TYPE_CHECKING:
    from ..db.connection import Connection

# Released programs first (draft false sorts first), the newest of them.
PROGRAM_TO_DRAW = "SELECT id, draft FROM program WHERE job_id = %s ORDER BY draft, id DESC LIMIT 1"


def plot_hobbing_job(conn: Connection, job_id: int, out) -> list[str]:
    """Draw the job's program that reaches the machine to `out`; → one line per thing drawn."""
    program_id, draft = program_to_draw(conn, job_id)
    return [f"program {program_id} ({which_program(draft)})", *plot_stored_program(conn, program_id, out)]


def program_to_draw(conn: Connection, job_id: int) -> tuple[int, bool]:
    row = conn.execute(PROGRAM_TO_DRAW, (job_id,)).fetchone()
    if row is None:
        raise EngineError(f"job {job_id} has no stored program to draw; "
                          f"make one with `engine instantiate --job {job_id}`")
    return row


def which_program(draft: bool) -> str:
    if draft:
        return "a draft, the job's newest: it has no program of a released template version"
    return "the job's newest of a released template version"
