"""Work-holdings as read from the database (table work_holding, issue 29): the arbor, mandrel,
collet or centres a hobbing job is clamped on instead of the machine record's fixture and
tailstock. The part under the gear is a cylinder of `diameter` over `height` (mm), its top face the
machine record's fixture_gap below the gear's bottom face, the machine's own fixture below it; the
centre above the top face has `tailstock_diameter` (0: none), the machine's tailstock_gap above it."""
from __future__ import annotations

from typing import TYPE_CHECKING

import msgspec
from msgspec.structs import replace

from ..db.records import as_float, columns
from ..errors import EngineError

if TYPE_CHECKING:
    from ..db.connection import Connection
    from .records import Machine

KINDS = ("arbor", "mandrel", "collet", "centres")


class WorkHolding(msgspec.Struct, frozen=True):
    """A work-holding of the library: its id (printed as `; FIXTURE <id>`), kind and sizes (mm),
    and the machine it fits (None: any hobber)."""
    id: str
    kind: str
    diameter: float
    height: float
    tailstock_diameter: float = 0.0
    machine: str | None = None


HOLDING_QUERY = f"SELECT {columns(WorkHolding)} FROM work_holding"  # static, from the record's fields


def load_work_holdings(conn: Connection) -> list[WorkHolding]:
    """Every work-holding of the library, by id."""
    return [as_float(WorkHolding, row, "work-holding") for row in conn.execute(HOLDING_QUERY + " ORDER BY id")]


def load_work_holding(conn: Connection, holding_id: str) -> WorkHolding:
    """The work-holding of this id (any case), or EngineError naming the library's command."""
    row = conn.execute(HOLDING_QUERY + " WHERE upper(id) = upper(%s)", (holding_id,)).fetchone()
    if row is None:
        raise EngineError(f"work-holding {holding_id!r} does not exist; see `engine fixtures list`")
    return as_float(WorkHolding, row, "work-holding")


def job_work_holding(conn: Connection, job_id: int | None) -> WorkHolding | None:
    """The work-holding a stored job is clamped on; None: the machine record's fixture and tailstock."""
    if job_id is None:
        return None
    found = conn.execute("SELECT work_holding_id FROM job WHERE id = %s", (job_id,)).fetchone()
    return load_work_holding(conn, found[0]) if found and found[0] is not None else None


def jobs_work_holdings(conn: Connection, job_ids: list[int]) -> dict[int, WorkHolding | None]:
    """job_work_holding of each of the jobs (one that does not exist: None), in one query for the jobs
    and one per distinct work-holding: the release impact reads thousands of jobs' before its workers
    start (issue 28)."""
    rows = conn.execute("SELECT id, work_holding_id FROM job WHERE id = ANY(%s)", (job_ids,)).fetchall()
    holdings = {holding_id: load_work_holding(conn, holding_id) for holding_id in {row[1] for row in rows} - {None}}
    named = {job_id: holdings[holding_id] for job_id, holding_id in rows if holding_id is not None}
    return {job_id: named.get(job_id) for job_id in job_ids}


def clamped_on(machine: Machine, holding: WorkHolding | None) -> Machine:
    """The machine as the hob meets it with this work-holding: its tailstock the holding's centre
    (the gaps stay the machine's). The part under the gear is added by the simulation's solids."""
    if holding is None:
        return machine
    return replace(machine, tailstock_diameter=holding.tailstock_diameter)
