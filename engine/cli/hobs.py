"""`engine hobs …`: the hob library (list, show, add, import, delete, match)."""
from __future__ import annotations

import click

from .context import connection, emit_json, keyed, record_dict
from .ids import GEAR_ID
from .output import Column, emit_list, emit_record, list_options

HOB_COLUMNS = (
    Column("id", "hob_id"), Column("module", "module"), Column("kind", "module_kind"), Column("α", "pressure_angle"),
    Column("starts", "starts"), Column("da0", "tip_diameter"), Column("length", "length"), Column("hand", "hand"),
    Column("class", "accuracy_class"), Column("material", "material"), Column("coating", "coating"),
    Column("purpose", "purpose"), Column("T", "tool_number"), Column("gashes", "gashes"),
    Column("profile", "profile"),
)
HOB_FIELDS = (
    Column("hob", "hob_id"), Column("module", "module"), Column("module kind", "module_kind"),
    Column("pressure angle", "pressure_angle"),
    Column("starts", "starts"), Column("tip diameter", "tip_diameter"), Column("length", "length"),
    Column("hand", "hand"), Column("accuracy class", "accuracy_class"), Column("material", "material"),
    Column("coating", "coating"), Column("purpose", "purpose"), Column("tool number", "tool_number"),
    Column("gashes", "gashes"), Column("profile", "profile"),
)
JOB_COLUMNS = (Column("job", "job_id"), Column("gear", "gear_id"), Column("class", "class"),
               Column("machine", "machine"), Column("made", "created_at"))


@click.group("hobs")
def hobs():
    """Hob library: list, show, add, import from CSV, delete, and match a hob to a gear."""


@hobs.command("list")
@list_options("hobs")
@click.pass_context
def hobs_list(ctx, output):
    """Every hob of the library, one line each (module, α, starts, da0, length, hand, class, ...).
    --csv writes the file `engine hobs import` reads (its columns, id first; every value as stored),
    which `engine hobs import FILE --replace` takes back unchanged; --json the same fields, the id
    as hob_id.

    Example: engine hobs list --csv > hobs.csv
    """
    from ..gears.hob_library import export_hobs
    from ..gears.hob_records import hob_records

    with connection(ctx) as conn:
        library = hob_records(conn) if output is None else export_hobs(conn)
    if output == "csv":   # the columns `hobs import` reads: its id column is `id`
        emit_list(output, "hobs", (Column("id", "id"), *HOB_COLUMNS[1:]), library)
    else:
        emit_list(output, "hobs", HOB_COLUMNS, [keyed(hob, id="hob_id") for hob in library] if output else library)


@hobs.command("show")
@click.argument("hob_id")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON line: {\"hob\": {..., jobs}}.")
@click.pass_context
def hobs_show(ctx, hob_id, as_json):
    """One hob as stored (its id in any case) and the jobs that use it.

    Example: engine hobs show H-M2-AA-R1
    """
    from ..gears.hob_records import hob_details

    with connection(ctx) as conn:
        hob = hob_details(conn, hob_id)
    emit_record(as_json, "hob", HOB_FIELDS, hob, (("jobs", JOB_COLUMNS, "jobs"),))


@hobs.command("delete")
@click.argument("hob_id")
@click.option("--yes", is_flag=True, help="Delete it (without: say what would be deleted, exit 1).")
@click.pass_context
def hobs_delete(ctx, hob_id, yes):
    """Delete a hob no job refers to.

    Example: engine hobs delete H-M5-B-L1 --yes
    """
    from ..gears.hob_records import delete_hob

    with connection(ctx) as conn:
        deleted = delete_hob(conn, hob_id, yes)
    click.echo(f"deleted {deleted}")


@hobs.command("add")
@click.option("--id", "hob_id", required=True, help="Hob id (unique), e.g. H-M2-AA-R1.")
@click.option("--module", type=float, required=True,
              help="Module, mm: the normal module m_n, or with --module-kind axial the worm's axial module m_x.")
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
@click.option("--module-kind", type=click.Choice(["normal", "axial"]), default=None,
              help="Which module --module is: normal (default for cylindrical hobs) or axial (a worm-wheel hob "
                   "catalogued by its worm's axial module, DIN 3975). A worm-wheel hob must say.")
@click.option("--gashes", type=int, default=12, show_default=True,
              help="Gashes (flutes) of the hob, 1 to 40; with the starts they bound the feed by the chip thickness.")
@click.option("--profile", type=click.Choice(["standard", "protuberance", "topping"]), default="standard",
              show_default=True, help="Tooth profile: the basic rack's, with a tip protuberance, or topping.")
@click.pass_context
def hobs_add(ctx, hob_id, module, pressure_angle, starts, tip_diameter, length, hand, accuracy_class,
             material, coating, purpose, tool_number, module_kind, gashes, profile):
    """Add one hob to the library; a bad value or an existing id stores nothing."""
    from ..gears.hob_library import add_hob
    from ..gears.records import Hob

    hob = Hob(hob_id, module, pressure_angle, starts, tip_diameter, length, hand, accuracy_class,
              material, coating, purpose, tool_number, module_kind or "", gashes, profile)
    with connection(ctx) as conn:
        add_hob(conn, hob)
    click.echo(f"added hob {hob_id}")


@hobs.command("import")
@click.argument("csv_file", type=click.Path(dir_okay=False))
@click.option("--replace", is_flag=True,
              help="Replace each stored hob of the file whole: the file must give every column.")
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object: {added: N, updated: N, kept: [columns]}.")
@click.pass_context
def hobs_import(ctx, csv_file, replace, as_json):
    """Add or update (by id) the hobs of CSV_FILE (the columns of `engine hobs list --csv`);
    any bad row stops the whole file (nothing stored). A hob already in the library is updated
    in the columns the file gives only: a column the file leaves out (an older file without
    tool_number, gashes or profile) keeps each hob's own value, and the output names it; with
    --replace a column left out is refused. A hob a stored job was made with is changed in no
    column (give the changed hob a new id): its programs were proved on it.

    Example: engine hobs list --csv > hobs.csv; (edit); engine hobs import hobs.csv --replace"""
    from ..gears.hob_library import import_hobs

    with connection(ctx) as conn:
        result = import_hobs(conn, csv_file, replace=replace)
    if as_json:
        emit_json(record_dict(result))
    else:
        kept = f" (not in the file, kept as they were: {', '.join(result.kept)})" if result.kept else ""
        click.echo(f"{csv_file}: added {result.added} hob(s), updated {result.updated}{kept}")


@hobs.command("match")
@click.option("--gear", "gear_id", type=GEAR_ID, required=True, help="Gear id.")
@click.option("--shift-travel", type=float, default=0.0, show_default=True,
              help="Hob shift the job will use, mm (the hob must be this much longer).")
@click.option("--purpose", type=click.Choice(["cylindrical", "worm_wheel"]),
              help="Hob purpose (default: worm_wheel for worm-wheel classes, else cylindrical).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON line: {gear_id, hob_id, reason}.")
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
