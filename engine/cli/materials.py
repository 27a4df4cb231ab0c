"""`engine materials …`: the workpiece materials and their §C cutting speeds (list, show, import), issue 31."""
from __future__ import annotations

import click
from msgspec.structs import asdict

from .context import connection, emit_json
from .output import Column, emit_list, emit_record, list_options

# The keys are the columns of `engine materials import`: `list --csv` is a file it reads back.
MATERIAL_COLUMNS = (
    Column("name", "name"), Column("group", "material_group"), Column("HB min", "hardness_min"),
    Column("HB max", "hardness_max"), Column("HSS low", "uncoated_low"), Column("HSS high", "uncoated_high"),
    Column("coated low", "coated_low"), Column("coated high", "coated_high"), Column("carbide low", "carbide_low"),
    Column("carbide high", "carbide_high"), Column("HSS v0", "default_uncoated"),
    Column("coated v0", "default_coated"), Column("source", "source"),
)
MATERIAL_FIELDS = (
    Column("material", "name"), Column("group", "material_group"), Column("hardness min (HB)", "hardness_min"),
    Column("hardness max (HB)", "hardness_max"), Column("uncoated HSS v (m/min) low", "uncoated_low"),
    Column("uncoated HSS v (m/min) high", "uncoated_high"), Column("coated HSS v (m/min) low", "coated_low"),
    Column("coated HSS v (m/min) high", "coated_high"), Column("carbide v (m/min) low", "carbide_low"),
    Column("carbide v (m/min) high", "carbide_high"),
    Column("v with no history, uncoated (m/min)", "default_uncoated"),
    Column("v with no history, coated (m/min)", "default_coated"), Column("source", "source"),
    Column("gears of it", "gear_count"),
)


@click.group("materials")
def materials():
    """Workpiece materials: group, hardness and the cutting speeds of reference §C by hob material and
    coating (list, show, import). A gear whose material is not here is refused at instantiate.

    Example: engine materials list
    """


@materials.command("list")
@list_options("materials")
@click.pass_context
def materials_list(ctx, output):
    """Every material, one line each: group, hardness range (HB), v [m/min] low and high for uncoated HSS,
    coated HSS and carbide hobs, the v a job with no machining history takes (uncoated, coated), and the
    source of the numbers. --csv writes the file `engine materials import` reads (every value as stored),
    which `engine materials import FILE --replace` takes back unchanged.

    Example: engine materials list --csv > materials.csv
    """
    from ..gears.materials import list_materials

    with connection(ctx) as conn:
        rows = list_materials(conn)
    emit_list(output, "materials", MATERIAL_COLUMNS, rows)


@materials.command("show")
@click.argument("name")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON line: {\"material\": {...}}.")
@click.pass_context
def materials_show(ctx, name, as_json):
    """One material (its name in any case) and how many stored gears are of it.

    Example: engine materials show 42CrMo4
    """
    from ..gears.materials import show_material

    with connection(ctx) as conn:
        record = show_material(conn, name)
    emit_record(as_json, "material", MATERIAL_FIELDS, record)


@materials.command("import")
@click.argument("csv_file", type=click.Path(dir_okay=False))
@click.option("--replace", is_flag=True,
              help="Replace each stored material of the file whole: the file must give every column.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {added: N, updated: N}.")
@click.pass_context
def materials_import(ctx, csv_file, replace, as_json):
    """Add or update (by name) the materials of CSV_FILE (the columns of `engine materials list --csv`:
    name,material_group,hardness_min,hardness_max,uncoated_low,uncoated_high,coated_low,coated_high,
    carbide_low,carbide_high,default_uncoated,default_coated,source); any bad row stops the whole file
    (nothing stored). A changed speed applies to programs made from then on.

    Example: engine materials import materials.csv
    """
    from ..gears.materials import import_materials

    with connection(ctx) as conn:
        result = import_materials(conn, csv_file, replace=replace)
    if as_json:
        emit_json(asdict(result))
    else:
        click.echo(f"{csv_file}: added {result.added} material(s), updated {result.updated}")
