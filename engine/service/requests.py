"""What each machine was sent (issue 32): the records of table program_request, newest first,
each with the template version its program was made from (the program's record). A request is
written by the delivery (FTP, the request folder, a runner's request on the web view); this only
reads them, for the machine's page and its JSON. At a head office a machine's requests include
those its plants' controls of that machine record made (issue 33): `plant` says where each was
asked (0: the head office)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..db.connection import scalar
from ..db.listing import records
from ..db.origin import MADE_AT_SQL

if TYPE_CHECKING:
    from ..db.connection import Connection

SHOWN_REQUESTS = 200   # newest requests a machine's page lists (the count says how many there are)

REQUESTS = """
SELECT r.id AS request_id, """ + MADE_AT_SQL.format(id="r.id") + """ AS plant,
       r.machine, r.via, r.client, r.asked_for, r.job_id, r.program_id, r.refusal,
       r.requested_at, r.requested_by, p.gear_class AS class, p.template_version, p.template_hash, p.draft
FROM program_request r LEFT JOIN program p ON p.id = r.program_id
WHERE r.machine = %s
ORDER BY r.requested_at DESC, r.id DESC
LIMIT %s"""
COUNT = "SELECT count(*)::int FROM program_request WHERE machine = %s"


def machine_requests(conn: Connection, machine: str, limit: int = SHOWN_REQUESTS) -> tuple[list[dict[str, Any]], int]:
    """(the machine's newest `limit` requests, how many it has in all). A request refused has
    its one-line reason in `refusal` and no program; one sent names its program, job and the class
    and template version the program was made from."""
    found = records(conn.execute(REQUESTS, (machine, limit)))
    for request in found:
        request["requested_at"] = request["requested_at"].isoformat()
    return found, scalar(conn.execute(COUNT, (machine,)))
