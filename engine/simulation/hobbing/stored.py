"""A stored program simulated against the records of its job (`engine simulate --program ID`):
its lines, the job's gear (with its units), hob, machine and work-holding as the database holds them now; a
lathe program is handed to the turning simulation (engine.simulation.turning.stored)."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ...errors import EngineError
from ...gears.records import Hob, load_gear, load_hobs
from ...machines.records import load_machine
from ...machines.work_holding import load_work_holding
from .report import Report
from .run import simulate_program

if TYPE_CHECKING:
    from ...db.connection import Connection

PROGRAM_QUERY = """
SELECT p.name, p.lines, j.gear_id, j.hob_id, j.machine, j.work_holding_id
FROM program p JOIN job j ON j.id = p.job_id
WHERE p.id = %s"""


def simulate_stored_program(conn: Connection, program_id: int) -> Report:
    row = conn.execute(PROGRAM_QUERY, (program_id,)).fetchone()
    if row is None:
        raise EngineError(f"program {program_id} does not exist; see `SELECT id, name FROM program`")
    name, lines, gear_id, hob_id, machine_name, holding_id = row
    machine = load_machine(conn, machine_name)
    if machine.kind == "lathe":
        from ..turning.stored import simulate_stored_turning  # the lathe's part of the simulation

        return simulate_stored_turning(conn, program_id, name, list(lines), machine)
    if machine.kind != "hobber" or gear_id is None or hob_id is None:
        raise EngineError(f"program {program_id} is not a hobbing program (machine {machine_name}, "
                          f"gear {gear_id}, hob {hob_id}): the simulation follows hobbing programs only")
    holding = load_work_holding(conn, holding_id) if holding_id is not None else None
    return simulate_program(list(lines), load_gear(conn, gear_id), load_hob(conn, hob_id), machine, name, holding)


def load_hob(conn: Connection, hob_id: str) -> Hob:
    """The hob record (the library is small: read whole, as instantiation reads it)."""
    found = next((hob for hob in load_hobs(conn) if hob.id == hob_id), None)
    if found is None:
        raise EngineError(f"hob {hob_id!r} does not exist; see `engine hobs list`")
    return found
