"""Which database made a record (issue 33; docs/design.md §12): each database makes ids of its own
range only (plant N: N·10^10 to (N+1)·10^10 − 1, the head office from 1), so a job, program, request
or drawing whose id is outside this database's range was made at another plant and reached this one
by replication. Its gear, hob and machine records are that plant's (gears are never replicated, and
gear ids may collide), so no screen here proves it against this database's records: it says where
it was made and that it was proved there (engine.programs.rendering: PLANT)."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..errors import EngineError
from .connection import scalar

if TYPE_CHECKING:
    from .connection import Connection

PLANT_IDS = 10**10   # the size of one plant's id range (migration 0042's plant_first_id)
LAST_PLANT = 9999    # the greatest plant number (migration 0042's plant_identity.number check)
# SQL of the plant that made the row with id column `id` (psycopg.sql would quote the alias away)
MADE_AT_SQL = "({id} / " + str(PLANT_IDS) + ")::int"
# SQL: true of a row this database made (its id in this database's range)
MADE_HERE_SQL = "{id} BETWEEN plant_first_id(plant_number()) AND plant_last_id(plant_number())"

# SQL: the row's gear id names a gear of the plant filtered on (%(plant)s), this database's without one
GEAR_PLANT = "(" + MADE_AT_SQL + " = coalesce(%(plant)s::int, plant_number()))"


def made_at(record_id: int) -> int:
    """The plant that made the record with this id (0: the head office, or a single database)."""
    return record_id // PLANT_IDS


def this_plant(conn: Connection) -> int:
    """This database's plant number: 0 at the head office or a database without plants."""
    return int(scalar(conn.execute("SELECT plant_number()")))


def made_elsewhere(conn: Connection, record_id: int) -> int | None:
    """The plant that made the record, if it is not this database; None for a record made here."""
    plant = made_at(record_id)
    return None if plant == this_plant(conn) else plant


def refuse_elsewhere(conn: Connection, kind: str, record_id: int, doing: str) -> None:
    """EngineError (one line) if another plant made the record: `doing` needs that plant's gear, hob
    and machine records, so it is done there (e.g. "make and send it there")."""
    refuse_unless_made_at(this_plant(conn), kind, record_id, doing)


def refuse_unless_made_at(here: int, kind: str, record_id: int, doing: str) -> None:
    """refuse_elsewhere with this database's plant number read once (a batch of jobs)."""
    plant = made_at(record_id)
    if plant != here:
        raise EngineError(f"{kind} {record_id} was made at {plant_name(plant)}: {doing} there "
                          "(its gear, hob and machine records are the plant's)")


def plant_name(plant: int) -> str:
    return "the head office" if plant == 0 else f"plant {plant}"
