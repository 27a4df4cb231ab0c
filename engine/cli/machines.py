"""`engine machines list|show|import`: the machine records, each with its kind, its NC dialect (the grammar the
verifier reads its programs in), its travel and spindle limit and, for ISO lathes, the control's
facts the record states (G-code system, decimal point input, power-on modes); `--csv` every column
of the record, as `engine machines import` reads it. `engine machines import`: new machine records
from such a file (engine.machines.importing)."""
from __future__ import annotations

import click
from msgspec import to_builtins
from msgspec.structs import asdict

from .context import connection, emit_json
from .output import Column, csv_text, emit_list, emit_record, list_options

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
    from ..machines.importing import export_machines
    from ..machines.records import all_machines, floor_times_said, unstated_floor_times

    with connection(ctx) as conn:
        if output == "csv":   # each value as stored, digit for digit: what `import --replace` takes back
            click.echo(csv_text(every_column(), export_machines(conn)), nl=False)
            return
        machines = all_machines(conn)
    records = [asdict(machine) for machine in machines]
    if output != "json":   # the table's word for the times --json and --csv give field by field
        for record, machine in zip(records, machines):
            record["floor_to_floor"] = floor_times_said(machine.kind, unstated_floor_times(machine))
    emit_list(output, "machines", MACHINE_COLUMNS, records)


@machines.command("show")
@click.argument("name")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON line: {\"machine\": {...}}.")
@click.pass_context
def machines_show(ctx, name, as_json):
    """One machine record, every field (travel in mm, speeds in r/min, times in s), and how many
    stored jobs were made on it.

    Example: engine machines show hobber-840d
    """
    from ..machines.importing import show_machine

    with connection(ctx) as conn:
        record = show_machine(conn, name)
    emit_record(as_json, "machine", (*every_column(), Column("jobs", "job_count")), record)


@machines.command("import")
@click.argument("csv_file", type=click.Path(dir_okay=False))
@click.option("--replace", is_flag=True,
              help="Replace each stored machine of the file whole (an empty cell: the column's default); one stored "
                   "jobs were made on is changed in no field.")
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object: {added: [names], replaced: [names], changes: [...]}.")
@click.pass_context
def machines_import(ctx, csv_file, replace, as_json):
    """Add the machines of CSV_FILE (the columns `engine machines list --csv` writes; name, kind,
    dialect, the travel x_min, x_max, z_min, z_max and spindle_max required, an empty cell the
    column's default). Without --replace only new machines: one that exists is refused; with it,
    each stored one is replaced whole, every changed field said old → new, except that a machine
    stored jobs were made on is changed in no field (their programs were proved on it: give a
    changed one a new name). Any bad row stops the whole file, nothing stored. A hobber stating
    some floor-to-floor times but not all is added with a note naming the ones missing (its
    programs have no FLOOR TO FLOOR line). Needs the role engine_planner.

    Example: engine machines list --csv > machines.csv && engine machines import machines.csv --replace
    """
    from ..machines.importing import import_machines, partial_floor_time_notes
    from ..verifier.grammar import DIALECTS

    with connection(ctx) as conn:
        done = import_machines(conn, csv_file, set(DIALECTS), record_fault, replace=replace)
    for note in partial_floor_time_notes(csv_file):
        click.echo(f"note: {note}", err=True)
    if as_json:
        return emit_json(to_builtins(done))
    for change in done.changes:
        click.echo(change.said("machine"))
    replaced = f", replaced {len(done.replaced)}" if replace else ""
    click.echo(f"{csv_file}: added {len(done.added)} machine(s): {', '.join(done.added) or '-'}{replaced}")


def record_fault(machine: dict) -> str | None:
    """Why the verifier could never take an ISO lathe's record as it is (a power-on state its
    control cannot be in: G90 on G-code system A, two codes of one modal group), or None."""
    if machine["dialect"] != "iso" or not machine.get("power_on"):
        return None
    from ..verifier.expanders.iso_rules import power_on_fault

    return power_on_fault(machine["power_on"].split(), machine.get("gcode_system"))
