"""`engine gears import|units` and `engine classify`: workpieces and their class."""
from __future__ import annotations

import click

from .context import connection, emit_json
from .gear_records import GEAR_RECORD_COMMANDS
from .ids import GEAR_ID


@click.group()
def gears():
    """Workpieces: import them from CSV (columns of design notes §9)."""


for _command in GEAR_RECORD_COMMANDS:   # list, show, delete: engine.cli.gear_records
    gears.add_command(_command)


@gears.command("import")
@click.argument("csv_file", type=click.Path(dir_okay=False))
@click.option("--replace", is_flag=True,
              help="Overwrite gears whose gear_id is already stored, printing each changed field (old → new).")
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object: {imported: N, replaced: [gear_id…], changes: [{gear_id, field, old, new}]}.")
@click.pass_context
def gears_import(ctx, csv_file, replace, as_json):
    """Import gears from CSV_FILE (`,` or `;` between the columns; with `;` a decimal comma is read as
    a point). Any bad row stops the whole file (nothing stored). A gear_id already stored is refused
    unless --replace. The tip and root diameters of cylindrical gears must fit m_n, z, β and x.

    Example: engine gears import gears.csv --replace"""
    from ..gears.gear_store import import_gears

    with connection(ctx) as conn:
        result = import_gears(conn, csv_file, replace=replace)
    if as_json:
        emit_json(result.as_json())
        return
    for line in result.change_lines():
        click.echo(line)
    replaced = f" ({len(result.replaced)} replaced)" if result.replaced else ""
    click.echo(f"imported {result.imported} gear(s) from {csv_file}{replaced}")


@gears.command("units")
@click.argument("csv_file", type=click.Path(dir_okay=False))
@click.pass_context
def gears_units(ctx, csv_file):
    """Import further toothed units of multi-unit (duplex) gears from CSV_FILE.

    Columns: gear_id, unit (2: class duplex cuts two units per set-up, the gear row and unit 2),
    teeth, face_width, tip_diameter, root_diameter, z_top (Z of the unit's upper face; the gear's
    top face is Z = 0): the file `engine gears list --units --csv` writes. The units of each gear
    in the file replace its units; any bad row stops the whole file. The units of a gear a stored
    job was made from are replaced only by the same units (its programs were proved on them). A
    line is printed for a gear whose class does not cut further units."""
    from ..gears.units import import_units_noting

    with connection(ctx) as conn:
        count, notes = import_units_noting(conn, csv_file)
    for note in notes:
        click.echo(note)
    click.echo(f"imported {count} unit(s) from {csv_file}")


@click.command()
@click.option("--gear", "gear_id", type=GEAR_ID, required=True, help="Gear id.")
@click.pass_context
def classify(ctx, gear_id):
    """Explain a gear's class: the group-technology decision path (face-width variation,
    generating line, units), the class stored, its hobbing model and the hob it gets."""
    from ..gears.classify import explain_gear
    from ..programs import all_models  # noqa: F401  (registers every model)

    with connection(ctx) as conn:
        report = explain_gear(conn, gear_id)
    click.echo("\n".join(report.lines()))
