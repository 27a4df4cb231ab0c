"""`engine plot --program ID`: not drawn yet (issue 17, being built)."""
from __future__ import annotations

from ..errors import EngineError


def plot_stored_program(conn, program_id: int, out) -> list[str]:
    raise EngineError(f"program {program_id}: program plots are not built yet")
