"""The hob library as a person looks into it (`engine hobs list|show|delete`). A hob id is one hob
whatever its case (index hob_id_ignoring_case), so H-M2-AA-R1 and h-m2-aa-r1 find the same record. A hob a
job refers to is kept: the job's programs were cut with it."""
from __future__ import annotations

from typing import TYPE_CHECKING

from msgspec.structs import asdict

from ..db.listing import Deletion, Reference, delete_row, one_record, records
from .records import load_hobs

if TYPE_CHECKING:
    from ..db.connection import Connection

ONE_HOB = """
SELECT id AS hob_id, module, pressure_angle, starts, tip_diameter, length, hand, accuracy_class, material,
       coating, purpose, tool_number, module_kind, gashes, profile
FROM hob WHERE upper(id) = upper(%s)"""
HOB_JOBS = """
SELECT j.id AS job_id, j.gear_id, j.gear_class AS class, j.machine, j.created_at
FROM job j WHERE upper(j.hob_id) = upper(%s) ORDER BY j.id"""

HOB_DELETION = Deletion(
    kind="hob",
    lock_sql="""SELECT format('hob %%s (m%%s, %%s start(s), da0 %%s, %%s)', id, trim_scale(module), starts,
                              trim_scale(tip_diameter), purpose)
                FROM hob WHERE upper(id) = upper(%s) FOR UPDATE""",
    references=(Reference("job", "SELECT count(*) FROM job WHERE upper(hob_id) = upper(%s)"),),
    delete_sql="DELETE FROM hob WHERE upper(id) = upper(%s)",
    listing="engine hobs list",
)


def hob_records(conn: Connection) -> list[dict]:
    """Every hob of the library by id, its id under the common key hob_id."""
    return [_record(hob) for hob in load_hobs(conn)]


def _record(hob) -> dict:
    """The hob as its record gives it (the module in its own kind: what `hobs import` reads back)."""
    fields = {**asdict(hob), "module": hob.stated_module}
    return {"hob_id": fields.pop("id"), **fields}


def hob_details(conn: Connection, hob_id: str) -> dict:
    """The hob as stored and the jobs that use it."""
    hob = one_record(conn.execute(ONE_HOB, (hob_id,)), "hob", hob_id, "engine hobs list")
    return {**hob, "jobs": records(conn.execute(HOB_JOBS, (hob_id,)))}


def delete_hob(conn: Connection, hob_id: str, yes: bool) -> str:
    """Delete the hob if no job refers to it; what was deleted."""
    return delete_row(conn, HOB_DELETION, hob_id, yes)
