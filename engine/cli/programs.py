"""`engine programs …`: stored programs, found by id or by the hash on their lineage line."""
from __future__ import annotations

import click

from .context import connection, emit_json

RECORD_FIELDS = (  # (label, the value of a ProgramRecord)
    ("program", lambda record: record.id),
    ("name", lambda record: record.name),
    ("job", lambda record: record.job_id),
    ("gear", lambda record: record.gear_id if record.gear_id is not None else "-"),
    ("class", lambda record: record.gear_class),
    ("version", lambda record: f"v{record.template_version}" + (" (draft)" if record.draft else " (released)")),
    ("template hash", lambda record: record.template_hash),
    ("input hash", lambda record: record.input_hash or "-"),
    ("stored by", lambda record: record.stored_by or "-"),
    ("stored at", lambda record: record.created_at.isoformat(timespec="seconds")),
)


@click.group("programs")
def programs():
    """Stored programs: show one by id, or find it from the hash on its lineage line."""


@programs.command("show")
@click.argument("program_id", type=int, required=False)
@click.option("--hash", "prefix", metavar="H",
              help="8 or more hex digits of the INPUT or TEMPLATE hash on a program's lineage line; lists every match.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {programs: [{program_id, job_id, ..., lines}]}.")
@click.pass_context
def programs_show(ctx, program_id, prefix, as_json):
    """Show a stored program's record and its lines, by PROGRAM_ID or by --hash.

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
        if number:
            click.echo("")
        _echo_record(record)


def _echo_record(record) -> None:
    for label, value in RECORD_FIELDS:
        click.echo(f"{label + ':':15}{value(record)}")
    click.echo(f"{'lines:':15}{len(record.lines)}")
    for line in record.lines:
        click.echo(line)
