"""`engine plot --job ID` for a hobbing job: not drawn yet (issue 17, being built)."""
from __future__ import annotations

from ..errors import EngineError


def plot_hobbing_job(conn, job_id: int, out) -> list[str]:
    raise EngineError(f"job {job_id} is a hobbing job: hobbing plots are not built yet")
