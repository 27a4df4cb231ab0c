"""`engine programs …`: stored programs, listed by filters, or found by id or by the hash on their
lineage line."""
from __future__ import annotations

import click

from ..db.origin import LAST_PLANT, plant_name
from .context import connection, emit_json
from .ids import GEAR_ID, JOB_ID, PROGRAM_ID
from .output import Column, day, day_options, emit_list, list_options, one_of

PROGRAM_COLUMNS = (
    Column("program", "program_id"), Column("plant", "plant"), Column("name", "name"), Column("job", "job_id"),
    Column("gear", "gear_id"),
    Column("class", "class"), Column("version", "template_version"), Column("draft", "draft"),
    Column("verifier", "verifier"), Column("rendering", "rendering"),
    Column("template", "template_hash", lambda digest: digest[:8]),
    Column("input", "input_hash", lambda digest: (digest or "-")[:8]),
    Column("lines", "line_count"), Column("stored", "created_at"),
)

RECORD_FIELDS = (  # (label, the value of a ProgramRecord)
    ("program", lambda record: record.id),
    ("plant", lambda record: plant_name(record.plant)),
    ("name", lambda record: record.name),
    ("job", lambda record: record.job_id),
    ("gear", lambda record: "-" if record.gear_id is None else
     f"{record.gear_id} ({plant_name(record.plant)}'s, not this database's)" if _made_elsewhere(record) else
     record.gear_id),
    ("class", lambda record: record.gear_class),
    ("version", lambda record: f"v{record.template_version}" + (" (draft)" if record.draft else " (released)")),
    ("verifier", lambda record: record.verifier_said),
    ("rendering", lambda record: record.rendering.said if record.rendering else "not checked"),
    ("template hash", lambda record: record.template_hash),
    ("input hash", lambda record: record.input_hash or "-"),
    ("stored by", lambda record: record.stored_by or "-"),
    ("stored at", lambda record: record.created_at.isoformat(timespec="seconds")),
    ("layout", lambda record: record.layout.said),
)


@click.group("programs")
def programs():
    """Stored programs: list them, show one by id, or find it from the hash on its lineage line."""


@programs.command("list")
@click.option("--class", "gear_class", help="Only programs of this class.")
@click.option("--gear", "gear_id", type=GEAR_ID, help="Only programs made for this gear (a gear of --plant's, "
              "else of this database: gear ids of plants collide).")
@click.option("--plant", type=click.IntRange(0, LAST_PLANT),
              help="Only programs made at this plant (0: the head office).")
@click.option("--job", "job_id", type=JOB_ID, help="Only programs made from this job.")
@click.option("--draft", is_flag=True, help="Only programs made from a draft version (for trying).")
@click.option("--released", is_flag=True, help="Only programs made from a released version.")
@click.option("--check", is_flag=True, help="Render and prove every program listed again (a verifier reading and a "
              "simulation each): MATCH, MISMATCH or REFUSED in the rendering column instead of 'on show'.")
@day_options("programs stored")
@list_options("programs")
@click.pass_context
def programs_list(ctx, gear_class, gear_id, plant, job_id, draft, released, check, since, until, output):
    """The programs stored, one line each: name, job, gear, class, template version and hash,
    draft or released, read by the verifier or UNVERIFIED, whether its lines are the rendering
    of its version and job, number of lines, when stored (the text: `engine programs show ID`).

    The rendering column says UNCHECKED for a program whose job was edited since (it cannot be
    rendered again: not evidence), else 'on show' (`engine programs show ID` renders it), or with
    --check MATCH, MISMATCH or REFUSED (its lines are the rendering but the verifier or the
    simulation refuses them now). The verifier column says read only of a program checked now
    and MATCH; without --check, 'stored as verified, unchecked'.

    At a head office, the plant column says where each program was made: one made at a plant says
    PLANT (proved there when it was made; never re-proved here, where its gear, hob and machine
    records are not the plant's), also with --check.

    Example: engine programs list --gear 42 --released --since 2026-11-01
    """
    from ..programs.lookup import list_programs

    chosen = one_of(ctx, {"draft": draft, "released": released})
    kind = {"draft": True, "released": False}.get(chosen) if chosen is not None else None
    with connection(ctx) as conn:
        found = list_programs(conn, gear_class, gear_id, job_id, kind, day(since), day(until), check, plant)
    emit_list(output, "programs", PROGRAM_COLUMNS, found)


@programs.command("show")
@click.argument("program_id", type=PROGRAM_ID, required=False)
@click.option("--hash", "prefix", metavar="H",
              help="8 or more hex digits of the INPUT or TEMPLATE hash on a program's lineage line; lists every match.")
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON line: {programs: [{program_id, job_id, gear_id, class, ..., rendering: "
                   "{status, reason}, lines}]}.")
@click.pass_context
def programs_show(ctx, program_id, prefix, as_json):
    """Show a stored program's record and its lines, by PROGRAM_ID or by --hash. The lines are
    printed with the class's line ending and final newline (an imported class: its file's).

    Each program is first rendered again from its template version and its job's parameters
    and its rendering proved as a new program is: `rendering:` says MATCH, MISMATCH (its stored
    lines are not what the version makes: not the program the verifier read), REFUSED (they are,
    but the machine's verifier or the simulation refuses them now) or UNCHECKED (its job was edited since,
    so it cannot be rendered again; make it again with `engine instantiate --job ID`).

    The lineage line of a file on the control, e.g.
    `; PROGRAM 812 TEMPLATE spur v4 1f3a9c07 INPUT 5be02d11`, leads to its record
    (by the INPUT hash, every program made from the same job parameters).

    Example: engine programs show --hash 5be02d11
    """
    from ..programs.lookup import find_programs

    with connection(ctx) as conn:
        found = find_programs(conn, program_id, prefix)
    if as_json:
        emit_json({"programs": [record.as_dict() for record in found]})
        return
    for number, record in enumerate(found):
        if number:   # a blank line between programs (after one without a final newline, its line ends first)
            click.echo("" if found[number - 1].layout.final_newline else "\n")
        _echo_record(record)


def _made_elsewhere(record) -> bool:
    """Made at another plant (engine.programs.rendering: PLANT): its gear id is that plant's."""
    from ..programs.rendering import PLANT

    return record.rendering is not None and record.rendering.status == PLANT


def _echo_record(record) -> None:
    """The record, then the program with its class's line ending and final newline."""
    for label, value in RECORD_FIELDS:
        click.echo(f"{label + ':':15}{value(record)}")
    click.echo(f"{'lines:':15}{len(record.lines)}")
    click.echo(record.text, nl=False)
