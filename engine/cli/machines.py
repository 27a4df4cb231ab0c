"""`engine machines list`: the machine records, each with its kind, its NC dialect (the grammar the
verifier reads its programs in), its travel and spindle limit and, for ISO lathes, the control's
facts the record states (G-code system, decimal point input, power-on modes); `--csv` every column
of the record, as `engine machines import` reads it. `engine machines import`: new machine records
from such a file (engine.machines.importing)."""
from __future__ import annotations

import click
from msgspec.structs import asdict

from .context import connection, emit_json
from .output import Column, csv_text, emit_list, list_options

MACHINE_COLUMNS = (
    Column("machine", "name"), Column("kind", "kind"), Column("dialect", "dialect"),
    Column("X min", "x_min"), Column("X max", "x_max"), Column("Z min", "z_min"), Column("Z max", "z_max"),
    Column("spindle max", "spindle_max"), Column("G-code system", "gcode_system"),
    Column("decimal point", "decimal_point_input"), Column("power-on", "power_on"),
    Column("floor-to-floor", "floor_to_floor"),
)


def every_column() -> tuple[Column, ...]:
    """The record's every field, as --csv writes it and `engine machines import` reads it."""
    from ..machines.records import Machine

    return tuple(Column(name, name) for name in Machine.__struct_fields__)


@click.group("machines")
def machines():
    """Machine records: which machines exist, the dialect each runs and its limits.

    Example: engine machines list
    """


@machines.command("list")
@list_options("machines")
@click.pass_context
def machines_list(ctx, output):
    """Every machine record, one line each (kind, dialect, travel in mm, spindle r/min, ISO facts,
    and whether a hobber's programs state FLOOR TO FLOOR: yes, or the times it does not state).
    --json and --csv give every field of the record (the CSV as `engine machines import` reads it).
    Change a record in SQL (docs/guide/machines-and-simulation.md).

    Example: engine machines list --csv > machines.csv
    """
    from ..machines.records import all_machines, floor_times_said, unstated_floor_times

    with connection(ctx) as conn:
        machines = all_machines(conn)
    records = [asdict(machine) for machine in machines]
    if output == "csv":
        click.echo(csv_text(every_column(), records), nl=False)
        return
    if output != "json":   # the table's word for the times --json and --csv give field by field
        for record, machine in zip(records, machines):
            record["floor_to_floor"] = floor_times_said(machine.kind, unstated_floor_times(machine))
    emit_list(output, "machines", MACHINE_COLUMNS, records)


@machines.command("import")
@click.argument("csv_file", type=click.Path(dir_okay=False))
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {added: [names]}.")
@click.pass_context
def machines_import(ctx, csv_file, as_json):
    """Add the machines of CSV_FILE (the columns `engine machines list --csv` writes; name, kind,
    dialect, the travel x_min, x_max, z_min, z_max and spindle_max required, an empty cell the
    column's default). Only new machines: one that exists is refused (change it in SQL); any bad
    row stops the whole file, nothing stored. A hobber stating some floor-to-floor times but not
    all is added with a note naming the ones missing (its programs have no FLOOR TO FLOOR line).

    Example: engine machines import my_lathes.csv
    """
    from ..machines.importing import import_machines, partial_floor_time_notes
    from ..verifier.grammar import DIALECTS

    with connection(ctx) as conn:
        added = import_machines(conn, csv_file, set(DIALECTS), record_fault)
    for note in partial_floor_time_notes(csv_file):
        click.echo(f"note: {note}", err=True)
    if as_json:
        return emit_json({"added": added})
    click.echo(f"{csv_file}: added {len(added)} machine(s): {', '.join(added)}")


def record_fault(machine: dict) -> str | None:
    """Why the verifier could never take an ISO lathe's record as it is (a power-on state its
    control cannot be in: G90 on G-code system A, two codes of one modal group), or None."""
    if machine["dialect"] != "iso" or not machine.get("power_on"):
        return None
    from ..verifier.expanders.iso_rules import power_on_fault

    return power_on_fault(machine["power_on"].split(), machine.get("gcode_system"))
