"""`engine machines list`: the machine records, each with its kind, its NC dialect (the grammar the
verifier reads its programs in), its travel and spindle limit and, for ISO lathes, the control's
facts the record states (G-code system, decimal point input, power-on modes)."""
from __future__ import annotations

from dataclasses import asdict

import click

from .context import connection
from .output import Column, emit_list, list_options

MACHINE_COLUMNS = (
    Column("machine", "name"), Column("kind", "kind"), Column("dialect", "dialect"),
    Column("X min", "x_min"), Column("X max", "x_max"), Column("Z min", "z_min"), Column("Z max", "z_max"),
    Column("spindle max", "spindle_max"), Column("G-code system", "gcode_system"),
    Column("decimal point", "decimal_point_input"), Column("power-on", "power_on"),
)


@click.group("machines")
def machines():
    """Machine records: which machines exist, the dialect each runs and its limits.

    Example: engine machines list
    """


@machines.command("list")
@list_options("machines")
@click.pass_context
def machines_list(ctx, output):
    """Every machine record, one line each (kind, dialect, travel in mm, spindle r/min, ISO facts).
    --json gives every field of the record. Add or change a record in SQL (docs/guide/
    machines-and-simulation.md).

    Example: engine machines list --csv
    """
    from ..machines.records import all_machines

    with connection(ctx) as conn:
        records = [asdict(machine) for machine in all_machines(conn)]
    emit_list(output, "machines", MACHINE_COLUMNS, records)
