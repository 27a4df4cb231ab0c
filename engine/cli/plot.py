"""`engine plot`: a picture of a job (turning or hobbing) or of a stored program."""
from __future__ import annotations

from pathlib import Path

import click

from ..errors import EngineError
from .context import connection, emit_json, file_folder
from .ids import JOB_ID, PROGRAM_ID


@click.command("plot")
@click.option("--job", "job_id", type=JOB_ID, help="Job id: a turning job (engine import-dxf) or a hobbing job.")
@click.option("--program", "program_id", type=PROGRAM_ID, help="Stored program id: what its lines do, as the "
              "simulation reads them in its machine's dialect (840D, Fanuc).")
@click.option("-o", "--out", required=True, type=click.Path(dir_okay=False),
              help="Picture to write: FILE.png or FILE.svg; its folder must exist unless --mkdir.")
@click.option("--mkdir", is_flag=True, help="Create the folder of --out (and those above it) if missing.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: job_id or program_id, path, drawn.")
@click.pass_context
def plot_command(ctx, job_id, program_id, out, mkdir, as_json):
    """Draw a job (turning: profile, blank, every pass, X as diameter; hobbing: side view of
    blank, hob and passes, the numbers read from the program — swivel A with its sign, centre
    distance and depth per cut, feeds, shift range — and the gear's teeth beside the hob's
    thread; a worm wheel also from above) or a stored program, as PNG or SVG.

    Example: engine plot --job 7 -o job7.svg
    """
    from ..pictures import plot_format
    from ..programs.plots import plot_job, plot_program

    if (job_id is None) == (program_id is None):
        raise EngineError("give exactly one of --job ID, --program ID")
    plot_format(Path(out))   # a wrong suffix is refused before any folder is made
    file_folder(out, mkdir, "-o/--out")
    with connection(ctx) as conn:
        drawn = plot_job(conn, job_id, out) if job_id is not None else plot_program(conn, program_id, out)
    subject = {"job_id": job_id} if job_id is not None else {"program_id": program_id}
    if as_json:
        emit_json({**subject, "path": str(out), "drawn": drawn})
        return
    name = f"job {job_id}" if job_id is not None else f"program {program_id}"
    click.echo(f"{name} drawn to {out}: " + "; ".join(drawn))
