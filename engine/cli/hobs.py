"""`engine hobs …`: the hob library (list, add, import, match)."""
from __future__ import annotations

from dataclasses import asdict

import click

from .context import connection, emit_json, keyed

TABLE = (  # (heading, width, the cell of a hob)
    ("id", 14, lambda hob: hob.id),
    ("module", 6, lambda hob: f"{hob.module:g}"),
    ("α", 4, lambda hob: f"{hob.pressure_angle:g}"),
    ("starts", 6, lambda hob: str(hob.starts)),
    ("da0", 6, lambda hob: f"{hob.tip_diameter:g}"),
    ("length", 6, lambda hob: f"{hob.length:g}"),
    ("hand", 4, lambda hob: hob.hand),
    ("class", 5, lambda hob: hob.accuracy_class),
    ("material", 8, lambda hob: hob.material),
    ("coating", 7, lambda hob: hob.coating),
    ("purpose", 0, lambda hob: hob.purpose),
)


@click.group("hobs")
def hobs():
    """Hob library: list, add, import from CSV, and match a hob to a gear."""


@hobs.command("list")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {hobs: [...]}.")
@click.pass_context
def hobs_list(ctx, as_json):
    """Every hob of the library, one line each (module, α, starts, da0, length, hand, class, ...)."""
    from ..gears.hob_library import list_hobs

    with connection(ctx) as conn:
        library = list_hobs(conn)
    if as_json:
        emit_json({"hobs": [keyed(asdict(hob), id="hob_id") for hob in library]})
        return
    click.echo(" ".join(f"{heading:{width}}" for heading, width, _ in TABLE).rstrip())
    for hob in library:
        click.echo(" ".join(f"{cell(hob):{width}}" for _, width, cell in TABLE).rstrip())
    click.echo(f"{len(library)} hob(s)", err=True)


@hobs.command("add")
@click.option("--id", "hob_id", required=True, help="Hob id (unique), e.g. H-M2-AA-R1.")
@click.option("--module", type=float, required=True, help="Normal module m_n, mm.")
@click.option("--pressure-angle", type=float, default=20.0, show_default=True, help="Pressure angle α_n, degrees.")
@click.option("--starts", type=int, default=1, show_default=True, help="Number of starts z0.")
@click.option("--tip-diameter", type=float, required=True, help="Tip (outside) diameter da0, mm.")
@click.option("--length", type=float, required=True, help="Usable hob length, mm.")
@click.option("--hand", required=True, help="L or R.")
@click.option("--accuracy-class", required=True, help="AAA, AA, A, B, C or D.")
@click.option("--material", default="HSS", show_default=True, help="Hob material.")
@click.option("--coating", default="", help="Coating, e.g. TiN (empty: uncoated).")
@click.option("--purpose", default="cylindrical", show_default=True, help="cylindrical or worm_wheel.")
@click.option("--tool-number", type=int, default=1, show_default=True,
              help="The hob's place in the machine's tool list: the program calls T<n> D1.")
@click.pass_context
def hobs_add(ctx, hob_id, module, pressure_angle, starts, tip_diameter, length, hand, accuracy_class,
             material, coating, purpose, tool_number):
    """Add one hob to the library; a bad value or an existing id stores nothing."""
    from ..gears.hob_library import add_hob
    from ..gears.records import Hob

    hob = Hob(hob_id, module, pressure_angle, starts, tip_diameter, length, hand, accuracy_class,
              material, coating, purpose, tool_number)
    with connection(ctx) as conn:
        add_hob(conn, hob)
    click.echo(f"added hob {hob_id}")


@hobs.command("import")
@click.argument("csv_file", type=click.Path(dir_okay=False))
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {added: N, updated: N}.")
@click.pass_context
def hobs_import(ctx, csv_file, as_json):
    """Add or update (by id) the hobs of CSV_FILE (columns of seed_templates/hobs.csv);
    any bad row stops the whole file (nothing stored)."""
    from ..gears.hob_library import import_hobs

    with connection(ctx) as conn:
        result = import_hobs(conn, csv_file)
    if as_json:
        emit_json(asdict(result))
    else:
        click.echo(f"{csv_file}: added {result.added} hob(s), updated {result.updated}")


@hobs.command("match")
@click.option("--gear", "gear_id", type=int, required=True, help="Gear id.")
@click.option("--shift-travel", type=float, default=0.0, show_default=True,
              help="Hob shift the job will use, mm (the hob must be this much longer).")
@click.option("--purpose", type=click.Choice(["cylindrical", "worm_wheel"]),
              help="Hob purpose (default: worm_wheel for worm-wheel classes, else cylindrical).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {gear_id, hob_id, reason}.")
@click.pass_context
def hobs_match(ctx, gear_id, shift_travel, purpose, as_json):
    """The hob the engine would choose for a gear, and why (or which property no hob has)."""
    from ..gears.hob_library import match_hob

    with connection(ctx) as conn:
        choice = match_hob(conn, gear_id, purpose=purpose, shift_travel=shift_travel)
    if as_json:
        emit_json({"gear_id": gear_id, "hob_id": choice.hob.id, "reason": choice.reason})
    else:
        click.echo(f"gear {gear_id}: hob {choice.hob.id}")
        click.echo(f"  {choice.reason}")
