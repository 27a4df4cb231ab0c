"""`engine plot --job ID`: a stored turning job drawn with the passes exactly as
`engine instantiate --job ID` computes them from its (possibly edited) parameters, titled with
what identifies it on the shop floor: the job, its drawing, its machine and its program."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import EngineError
from .model import key, planned_passes
from .plot import JobPicture, job_figure, plot_picture

if TYPE_CHECKING:
    from ..db.connection import Connection

# The machine is the job row's (the one the program is made for); drawing and program name are
# job parameters (engine.turning.job_params), editable in SQL like the rest.
JOB_ROW = ("SELECT j.params, j.module_params, m.kind, j.machine FROM job j JOIN machine m ON m.name = j.machine "
           "WHERE j.id = %s")


def plot_turning_job(conn: Connection, job_id: int, out: str | Path) -> list[tuple[str, int, int]]:
    """Draw the job to `out` (.png or .svg); → (label, tool, passes) per operation drawn."""
    picture = job_picture(conn, job_id)
    plot_picture(out, picture)
    return [(label.removeprefix("OP "), tool, len(passes)) for label, tool, passes in picture.operations]


def turning_job_figure(conn: Connection, job_id: int):
    """The job's picture as a matplotlib Figure, not written (to read what is drawn)."""
    return job_figure(job_picture(conn, job_id))


def job_picture(conn: Connection, job_id: int) -> JobPicture:
    params, module_params, machine = turning_job_row(conn, job_id)
    geometry, planned = planned_passes(params, module_params)
    operations = [(operation_label(n, params, module_params), operation_tool(n, module_params), passes)
                  for n, passes in planned.items()]
    tool_change = (float(params["tool_change_z"]), float(params["tool_change_x"]))
    return JobPicture(geometry.outline, geometry.stock, operations, job_title(job_id, params, machine), tool_change)


def turning_job_row(conn: Connection, job_id: int) -> tuple[dict, dict, str]:
    row = conn.execute(JOB_ROW, (job_id,)).fetchone()
    if row is None:
        raise EngineError(f"job {job_id} does not exist; see `SELECT id, gear_class FROM job`")
    params, module_params, machine_kind, machine = row
    if machine_kind != "lathe":
        raise EngineError(f"job {job_id} is a {machine_kind} job, not a turning job; only turning jobs "
                          "(engine import-dxf) can be plotted")
    return params, module_params, machine


def operation_label(n: int, params: dict, module_params: dict) -> str:
    """'OP n KIND', as the program's operation comment; an alternated pair carries both numbers
    (operation A runs the passes of both, model.alternated_pair)."""
    kind = module_params[key("cutmotion", n)]["kind"]
    pair = params.get("alternate")
    if pair and pair[0] == n:
        return f"OP {n}+{pair[1]} {kind} alternated"
    return f"OP {n} {kind}"


def operation_tool(n: int, module_params: dict) -> int:
    return module_params.get(key("prep", n), {}).get("tool", n)


def job_title(job_id: int, params: dict, machine: str) -> str:
    return (f"job {job_id} · drawing {params.get('drawing')} · machine {machine} · "
            f"program {params.get('program_name')}")
