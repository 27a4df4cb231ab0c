"""Pictures of jobs and programs (issue 17): `engine plot --job ID` draws a turning job (the lathe's
passes, X as a diameter) or a hobbing job (a side view of blank, units, hob and passes), picked
by the kind of the job's machine; `engine plot --program ID` draws what a stored program does, by
the simulation's reading of its lines. A stored program is drawn only if it is the rendering of
the version and job it names (engine.programs.rendering). PNG or SVG by the file's suffix, written
whole or not at all."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import EngineError

if TYPE_CHECKING:
    from ..db.connection import Connection

JOB_MACHINE = "SELECT m.kind FROM job j JOIN machine m ON m.name = j.machine WHERE j.id = %s"


def plot_job(conn: Connection, job_id: int, out: str | Path) -> list[str]:
    """Draw the job to `out`; → one line per thing drawn (for the report). A job another plant
    made is drawn there, on its own gear (engine.db.origin)."""
    from ..db.origin import refuse_elsewhere

    row = conn.execute(JOB_MACHINE, (job_id,)).fetchone()
    if row is None:
        raise EngineError(f"job {job_id} does not exist; see `engine jobs list`")
    refuse_elsewhere(conn, "job", job_id, "draw it")
    plotter = JOB_PLOTTERS.get(row[0])
    if plotter is None:
        raise EngineError(f"job {job_id} runs on a {row[0]}, which has no plot; jobs of a lathe or a hobber are drawn")
    return plotter(conn, job_id, out)


def plot_program(conn: Connection, program_id: int, out: str | Path) -> list[str]:
    """Draw the stored program to `out` as the simulation reads it; → one line per thing drawn.
    Refused unless the program is the rendering of the version and job it names
    (engine.programs.rendering): a picture is evidence of what the program does."""
    from ..hobbing.program_plot import plot_stored_program
    from .rendering import checked_program

    checked_program(conn, program_id, "a picture")

    return plot_stored_program(conn, program_id, out)


def _turning(conn: Connection, job_id: int, out) -> list[str]:
    from ..turning.job_plot import plot_turning_job

    return [f"operation {label} T{tool}: {passes} pass(es)" for label, tool, passes in
            plot_turning_job(conn, job_id, out)]


def _hobbing(conn: Connection, job_id: int, out) -> list[str]:
    """A hobbing job is drawn by the stored program that reaches the machine: checked first."""
    from ..hobbing.job_plot import plot_hobbing_job, program_to_draw
    from .rendering import checked_program

    checked_program(conn, program_to_draw(conn, job_id)[0], f"a picture of job {job_id}")
    return plot_hobbing_job(conn, job_id, out)


JOB_PLOTTERS = {"lathe": _turning, "hobber": _hobbing}
