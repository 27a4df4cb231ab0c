"""`engine fixtures …`: the work-holding library (list, import, match), issue 29."""
from __future__ import annotations

import click

from .context import connection, emit_json, record_dict
from .ids import GEAR_ID
from .output import Column, emit_list, list_options

# The keys are the columns of `engine fixtures import`: `list --csv` is a file it reads back.
HOLDING_COLUMNS = (
    Column("id", "id"), Column("kind", "kind"), Column("diameter", "diameter"), Column("height", "height"),
    Column("centre", "tailstock_diameter"), Column("machine", "machine"),
)

MACHINE_OWN = "none (the machine's own fixture and tailstock)"


@click.group("fixtures")
def fixtures():
    """Work-holding library: arbors, mandrels, collets and centres a gear is clamped on (list, import, match).

    Example: engine fixtures match --gear 42
    """


@fixtures.command("list")
@list_options("fixtures")
@click.pass_context
def fixtures_list(ctx, output):
    """Every work-holding of the library, one line each (kind, diameter and height under the gear, centre
    diameter above, the machine it fits; empty: any). --csv and --json give every value as stored, in the
    columns `engine fixtures import` reads: `engine fixtures import FILE --replace` takes the CSV back
    unchanged.

    Example: engine fixtures list --csv > holdings.csv
    """
    from ..machines.holding_library import export_holdings, list_holdings

    with connection(ctx) as conn:
        library = list_holdings(conn) if output is None else export_holdings(conn)
    emit_list(output, "fixtures", HOLDING_COLUMNS, library)


@fixtures.command("import")
@click.argument("csv_file", type=click.Path(dir_okay=False))
@click.option("--replace", is_flag=True,
              help="Replace each stored work-holding of the file whole: the file must give every column.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {added: N, updated: N}.")
@click.pass_context
def fixtures_import(ctx, csv_file, replace, as_json):
    """Add or update (by id) the work-holdings of CSV_FILE (the columns of `engine fixtures list --csv`:
    id,kind,diameter,height,tailstock_diameter,machine); any bad row stops the whole file (nothing stored).
    A work-holding a stored job is clamped on is changed in no column (give the changed one a new id).

    Example: engine fixtures import holdings.csv --replace
    """
    from ..machines.holding_library import import_holdings

    with connection(ctx) as conn:
        result = import_holdings(conn, csv_file, replace=replace)
    if as_json:
        emit_json(record_dict(result))
    else:
        click.echo(f"{csv_file}: added {result.added} work-holding(s), updated {result.updated}")


@fixtures.command("match")
@click.option("--gear", "gear_id", type=GEAR_ID, required=True, help="Gear id.")
@click.option("--machine", help="Machine record (default: hobber-840d).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON line: {gear_id, hob_id, fixture_id, reason}.")
@click.pass_context
def fixtures_match(ctx, gear_id, machine, as_json):
    """The work-holding `engine instantiate --gear` would clamp the gear on, and why: the machine's own
    fixture and tailstock when they clear the root, else the largest of the library that does.

    Example: engine fixtures match --gear 42
    """
    from ..gears.holding_matching import match_holding

    with connection(ctx) as conn:
        hob, choice = match_holding(conn, gear_id, machine)
    fixture = choice.holding.id if choice.holding else None
    if as_json:
        emit_json({"gear_id": gear_id, "hob_id": hob.id, "fixture_id": fixture, "reason": choice.reason})
    else:
        click.echo(f"gear {gear_id}: fixture {fixture or MACHINE_OWN} (hob {hob.id})")
        click.echo(f"  {choice.reason}")
