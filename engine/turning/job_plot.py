"""`engine plot --job ID`: a stored turning job drawn with the passes exactly as
`engine instantiate --job ID` computes them from its (possibly edited) parameters."""
from __future__ import annotations

from pathlib import Path

from ..errors import EngineError
from .model import key, planned_passes
from .plot import plot_job


def plot_turning_job(conn, job_id: int, out: str | Path) -> list[tuple[str, int, int]]:
    """Draw the job to `out` (.png or .svg); → (label, tool, passes) per operation drawn."""
    row = conn.execute("SELECT j.params, j.module_params, m.kind FROM job j JOIN machine m ON m.name = j.machine "
                       "WHERE j.id = %s", (job_id,)).fetchone()
    if row is None:
        raise EngineError(f"job {job_id} does not exist; see `SELECT id, gear_class FROM job`")
    params, module_params, machine_kind = row
    if machine_kind != "lathe":
        raise EngineError(f"job {job_id} is a {machine_kind} job, not a turning job; only turning jobs "
                          "(engine import-dxf) can be plotted")
    geometry, planned = planned_passes(params, module_params)
    operations = []
    for n, passes in planned.items():
        kind = module_params[key("cutmotion", n)]["kind"]
        tool = module_params.get(key("prep", n), {}).get("tool", n)
        operations.append((f"{n} {kind}", tool, passes))
    plot_job(out, geometry.outline, geometry.stock, operations)
    return [(label, tool, len(passes)) for label, tool, passes in operations]
