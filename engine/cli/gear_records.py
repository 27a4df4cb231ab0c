"""`engine gears list|show|delete`: the workpieces stored, their units and jobs (registered on the
`gears` group of engine.cli.gears)."""
from __future__ import annotations

import click

from .context import connection
from .ids import GEAR_ID
from .output import Column, day, day_options, emit_list, emit_record, list_options

GEAR_COLUMNS = (
    Column("gear", "gear_id"), Column("class", "class"), Column("m", "module"), Column("z", "teeth"),
    Column("β", "helix_angle"), Column("hand", "hand"), Column("b", "face_width"), Column("material", "material"),
    Column("HB", "hardness"), Column("grade", "quality_grade"), Column("qty", "quantity"),
    Column("units", "unit_count"), Column("jobs", "job_count"), Column("stored", "created_at"),
)
GEAR_FIELDS = (
    Column("gear", "gear_id"), Column("class", "class"), Column("module", "module"),
    Column("module kind", "module_kind"), Column("teeth", "teeth"), Column("pressure angle", "pressure_angle"),
    Column("helix angle", "helix_angle"), Column("hand", "hand"), Column("face width", "face_width"),
    Column("tip diameter", "tip_diameter"), Column("root diameter", "root_diameter"),
    Column("cone angle", "cone_angle"), Column("crowning", "crowning"), Column("material", "material"),
    Column("hardness", "hardness"), Column("quality grade", "quality_grade"), Column("quantity", "quantity"),
    Column("profile shift", "profile_shift"), Column("stored", "created_at"),
)
UNIT_COLUMNS = (Column("unit", "unit"), Column("z", "teeth"), Column("b", "face_width"),
                Column("da", "tip_diameter"), Column("df", "root_diameter"), Column("z_top", "z_top"))
IMPORTED_UNIT_COLUMNS = (Column("gear", "gear_id"), *UNIT_COLUMNS)   # the columns `engine gears units` reads
JOB_COLUMNS = (Column("job", "job_id"), Column("class", "class"), Column("machine", "machine"),
               Column("hob", "hob_id"), Column("programs", "program_count"), Column("made", "created_at"),
               Column("confirmed", "confirmed_at"))


@click.command("list")
@click.option("--class", "gear_class", help="Only gears of this class.")
@click.option("--units", is_flag=True,
              help="List the gears' further toothed units instead (gear, unit, z, b, da, df, z_top).")
@day_options("gears stored")
@list_options("gears")
@click.pass_context
def gears_list(ctx, gear_class, units, since, until, output):
    """The gears stored, one line each: class, module, teeth, helix angle, face width, material,
    units, jobs, when stored. --csv writes the file `engine gears import` reads: its columns
    (gear_id, gear_class, … profile_shift), every value as stored, so `engine gears import FILE
    --replace` takes it back unchanged; with --units, the file `engine gears units` reads.

    Example: engine gears list --class spur --since 2026-01-01 --csv > gears.csv
    """
    from ..gears import gear_records

    listed = gear_records.export_units if units else gear_records.export_gears if output == "csv" \
        else gear_records.list_gears
    with connection(ctx) as conn:
        found = listed(conn, gear_class, day(since), day(until))
    columns = IMPORTED_UNIT_COLUMNS if units else imported_columns() if output == "csv" else GEAR_COLUMNS
    emit_list(output, "units" if units else "gears", columns, found)


def imported_columns() -> tuple[Column, ...]:
    """The columns of `engine gears import`, in its order: what --csv writes."""
    from ..gears.gear_import import COLUMNS

    return tuple(Column(column.name, column.name) for column in COLUMNS)


@click.command("show")
@click.argument("gear_id", type=GEAR_ID)
@click.option("--json", "as_json", is_flag=True, help="Print one JSON line: {\"gear\": {..., units, jobs}}.")
@click.pass_context
def gears_show(ctx, gear_id, as_json):
    """One gear as stored: its class and dimensions, its further toothed units, its jobs.

    Example: engine gears show 42
    """
    from ..gears.gear_records import gear_details

    with connection(ctx) as conn:
        gear = gear_details(conn, gear_id)
    emit_record(as_json, "gear", GEAR_FIELDS, gear, (("further units", UNIT_COLUMNS, "units"),
                                                     ("jobs", JOB_COLUMNS, "jobs")))


@click.command("delete")
@click.argument("gear_id", type=GEAR_ID)
@click.option("--yes", is_flag=True, help="Delete it (without: say what would be deleted, exit 1).")
@click.pass_context
def gears_delete(ctx, gear_id, yes):
    """Delete a gear (and its further units) that no job and no golden test refers to.

    Example: engine gears delete 90001 --yes
    """
    from ..gears.gear_records import delete_gear

    with connection(ctx) as conn:
        deleted = delete_gear(conn, gear_id, yes)
    click.echo(f"deleted {deleted}")


GEAR_RECORD_COMMANDS = (gears_list, gears_show, gears_delete)
