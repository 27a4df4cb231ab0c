"""The jobs stored, as a person looks into them (`engine jobs list|show|delete`): each job's gear,
class, machine and hob, its parameters, and the programs made from it. Programs are records
nobody rewrites, so a job with a program is never deleted; nor one whose cutting data became
cases of the machining history."""
from __future__ import annotations

from datetime import date
from typing import TYPE_CHECKING

from ..db.listing import Deletion, Reference, day_range, delete_row, one_record, records, require_class
from ..db.origin import GEAR_PLANT, MADE_AT_SQL
from .lookup import listed_verifier
from .rendering import LISTED_RENDERING

if TYPE_CHECKING:
    from ..db.connection import Connection

JOB_COLUMNS = """
SELECT j.id AS job_id, """ + MADE_AT_SQL.format(id="j.id") + """ AS plant,
       j.gear_id, j.gear_class AS class, j.machine, j.hob_id,
       (SELECT count(*) FROM program p WHERE p.job_id = j.id)::int AS program_count,
       j.created_at, j.confirmed_at"""
LIST_JOBS = JOB_COLUMNS + """
FROM job j
WHERE (%(class)s::text IS NULL OR j.gear_class = %(class)s)
  AND (%(plant)s::int IS NULL OR """ + MADE_AT_SQL.format(id="j.id") + """ = %(plant)s)
  AND (%(gear)s::int IS NULL OR (j.gear_id = %(gear)s AND """ + GEAR_PLANT.format(id="j.id") + """))
  AND (%(since)s::date IS NULL OR j.created_at >= %(since)s::date)
  AND (%(until)s::date IS NULL OR j.created_at < %(until)s::date + 1)
ORDER BY j.id"""
# Where a turning job's drawing record came from: a file import states the file's hash; a record
# without one was typed in SQL, or made by migration 0027 from a job's parameters. The record says
# who made it: a runner can insert one by hand (design notes §8, the drawing record).
DRAWING_SOURCE = """
(SELECT format('%%s: %%s, %%s, by %%s at %%s', d.id, d.file_name,
               CASE WHEN d.sha256 IS NOT NULL THEN 'file sha256 ' || left(d.sha256, 16) || '…'
                    ELSE 'no file hash (typed in SQL or made by a migration)' END,
               d.imported_by, to_char(d.imported_at, 'YYYY-MM-DD HH24:MI:SS'))
 FROM drawing d WHERE d.id = j.drawing_id) AS drawing"""
ONE_JOB = JOB_COLUMNS + ", j.params, j.module_params, j.cutting," + DRAWING_SOURCE + " FROM job j WHERE j.id = %s"
JOB_PROGRAMS = """
SELECT p.id AS program_id, p.name, p.template_version, p.draft, p.unverified, p.created_at,
       """ + LISTED_RENDERING + """ AS rendering
FROM program p JOIN job j ON j.id = p.job_id WHERE p.job_id = %s ORDER BY p.id"""

JOB_DELETION = Deletion(
    kind="job",
    lock_sql="""SELECT format('job %%s (gear %%s, class %%s, machine %%s)', id, coalesce(gear_id::text, '-'),
                              gear_class, machine)
                FROM job WHERE id = %s FOR UPDATE""",
    references=(Reference("program", "SELECT count(*) FROM program WHERE job_id = %s"),
                Reference("cutting case", "SELECT count(*) FROM cutting_case WHERE job_id = %s")),
    delete_sql="DELETE FROM job WHERE id = %s",
    listing="engine jobs list",
)


def list_jobs(conn: Connection, gear_class: str | None = None, gear_id: int | None = None, since: date | None = None,
              until: date | None = None, plant: int | None = None) -> list[dict]:
    """Every job of the class and gear (any if None) made from `since` to `until` (whole days,
    both included), at `plant` (any if None; `plant` of each: engine.db.origin), by id. A gear id
    is a gear of the plant named (this database's without one): gear ids of plants collide."""
    require_class(conn, gear_class)
    filters = {"class": gear_class, "gear": gear_id, "plant": plant, **day_range(since, until)}
    return records(conn.execute(LIST_JOBS, filters))


def job_details(conn: Connection, job_id: int) -> dict:
    """The job as stored (its parameters and cutting data included) and its programs."""
    job = one_record(conn.execute(ONE_JOB, (job_id,)), "job", job_id, "engine jobs list")
    programs = [{**program, "verifier": listed_verifier(program["unverified"], program["rendering"])}
                for program in records(conn.execute(JOB_PROGRAMS, (job_id,)))]
    return {**job, "programs": programs}


def delete_job(conn: Connection, job_id: int, yes: bool) -> str:
    """Delete the job if no program and no cutting case refers to it; what was deleted."""
    return delete_row(conn, JOB_DELETION, job_id, yes)
