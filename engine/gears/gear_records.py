"""The workpieces stored, as a person looks into them (`engine gears list|show|delete`): each gear
with its class, its toothed units and the jobs made for it. A gear a job or a golden test refers
to is kept: the job's programs were cut from it."""
from __future__ import annotations

from datetime import date
from typing import TYPE_CHECKING

from psycopg import sql

from ..db.listing import (
    Deletion,
    Reference,
    day_range,
    delete_row,
    exact_records,
    one_record,
    records,
    require_class,
)
from ..db.origin import MADE_HERE_SQL
from .gear_import import COLUMNS
from .units import UNIT_COLUMNS

if TYPE_CHECKING:
    from ..db.connection import Connection

GEAR_COLUMNS = """
SELECT g.id AS gear_id, g.gear_class AS class, g.module, g.module_kind, g.teeth, g.pressure_angle,
       g.helix_angle, g.hand, g.face_width, g.tip_diameter, g.root_diameter, g.cone_angle, g.crowning,
       g.material, g.hardness, g.quality_grade, g.quantity, g.profile_shift,
       1 + (SELECT count(*) FROM gear_unit u WHERE u.gear_id = g.id)::int AS unit_count,
       (SELECT count(*) FROM job j WHERE j.gear_id = g.id AND """ + MADE_HERE_SQL.format(id="j.id") + """)::int
       AS job_count, g.created_at
FROM gear g"""
GEAR_FILTER = """
WHERE (%(class)s::text IS NULL OR g.gear_class = %(class)s)
  AND (%(since)s::date IS NULL OR g.created_at >= %(since)s::date)
  AND (%(until)s::date IS NULL OR g.created_at < %(until)s::date + 1)"""
LIST_GEARS = GEAR_COLUMNS + GEAR_FILTER + "\nORDER BY g.id"
# The columns `engine gears import` reads, each under its name in the file (id AS gear_id).
EXPORT_GEARS = sql.SQL("SELECT {} FROM gear g" + GEAR_FILTER + " ORDER BY g.id").format(sql.SQL(", ").join(
    sql.SQL("g.{} AS {}").format(sql.Identifier(column.column), sql.Identifier(column.name)) for column in COLUMNS))
# The columns `engine gears units` reads, of the gears the filters choose.
EXPORT_UNITS = sql.SQL("SELECT {} FROM gear_unit u JOIN gear g ON g.id = u.gear_id" + GEAR_FILTER
                       + " ORDER BY u.gear_id, u.unit").format(
    sql.SQL(", ").join(sql.SQL("u.{}").format(sql.Identifier(column.name)) for column in UNIT_COLUMNS))
ONE_GEAR = GEAR_COLUMNS + " WHERE g.id = %s"
GEAR_UNITS = """
SELECT unit, teeth, face_width, tip_diameter, root_diameter, z_top FROM gear_unit WHERE gear_id = %s ORDER BY unit"""
# A gear's jobs are this database's: a plant's job of gear 44 (its history, at the head office) is of
# the plant's gear 44, another gear (issue 33, engine.db.origin).
GEAR_JOBS = """
SELECT j.id AS job_id, j.gear_class AS class, j.machine, j.hob_id, j.created_at, j.confirmed_at,
       (SELECT count(*) FROM program p WHERE p.job_id = j.id)::int AS program_count
FROM job j WHERE j.gear_id = %s AND """ + MADE_HERE_SQL.format(id="j.id") + """ ORDER BY j.id"""

GEAR_DELETION = Deletion(
    kind="gear",
    lock_sql="""SELECT format('gear %%s (class %%s, m%%s z%%s)', id, coalesce(gear_class, '-'),
                              trim_scale(module), teeth)
                || CASE WHEN EXISTS (SELECT 1 FROM gear_unit u WHERE u.gear_id = gear.id)
                        THEN ' and its further toothed units' ELSE '' END
                FROM gear WHERE id = %s FOR UPDATE""",
    references=(Reference("job", "SELECT count(*) FROM job WHERE gear_id = %s"),
                Reference("golden test", "SELECT count(*) FROM template_test WHERE gear_id = %s")),
    delete_sql="DELETE FROM gear WHERE id = %s",   # its units go with it (ON DELETE CASCADE)
    listing="engine gears list",
)


def list_gears(conn: Connection, gear_class: str | None = None, since: date | None = None,
               until: date | None = None) -> list[dict]:
    """Every gear of the class (any class if None) stored from `since` to `until` (whole days,
    both included), by id."""
    require_class(conn, gear_class)
    return records(conn.execute(LIST_GEARS, {"class": gear_class, **day_range(since, until)}))


def export_gears(conn: Connection, gear_class: str | None = None, since: date | None = None,
                 until: date | None = None) -> list[dict]:
    """list_gears's gears as `engine gears import` reads them: its columns, each value as stored
    (numbers digit for digit), by id."""
    require_class(conn, gear_class)
    return exact_records(conn.execute(EXPORT_GEARS, {"class": gear_class, **day_range(since, until)}))


def export_units(conn: Connection, gear_class: str | None = None, since: date | None = None,
                 until: date | None = None) -> list[dict]:
    """The further toothed units of list_gears's gears as `engine gears units` reads them, by gear
    and unit."""
    require_class(conn, gear_class)
    return exact_records(conn.execute(EXPORT_UNITS, {"class": gear_class, **day_range(since, until)}))


def gear_details(conn: Connection, gear_id: int) -> dict:
    """The gear as stored, its further toothed units (unit 1 is the gear itself) and its jobs."""
    gear = one_record(conn.execute(ONE_GEAR, (gear_id,)), "gear", gear_id, "engine gears list")
    return {**gear, "units": records(conn.execute(GEAR_UNITS, (gear_id,))),
            "jobs": records(conn.execute(GEAR_JOBS, (gear_id,)))}


def delete_gear(conn: Connection, gear_id: int, yes: bool) -> str:
    """Delete the gear (and its units) if no job or golden test refers to it; what was deleted."""
    return delete_row(conn, GEAR_DELETION, gear_id, yes)
