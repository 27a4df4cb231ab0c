"""`engine explain --program ID`: why each line of a stored program appeared, or did not, and
with which values (its trace)."""
from __future__ import annotations

import click

from .context import connection, emit_json
from .ids import PROGRAM_ID, ROW_ID


@click.command()
@click.option("--program", "program_id", type=PROGRAM_ID, required=True, help="Stored program id.")
@click.option("--row", "row_id", type=ROW_ID, help="Only this template row.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object: {program_id, rows: [...]}.")
@click.pass_context
def explain(ctx, program_id, row_id, as_json):
    """Say for every template row of a program whether it ran and emitted, and why.

    One line per row, e.g. `1800 not emitted: p_emit coolant = False (job)`; the values
    each expression read and where they came from (the job, a module's parameters, the
    row that computed them). The view program_trace has the same in SQL.

    Example: engine explain --program 7 --row 1400
    """
    from ..programs.explain import explain_program

    with connection(ctx) as conn:
        rows = explain_program(conn, program_id, row_id)
    if as_json:
        emit_json({"program_id": program_id, "rows": [row.as_dict() for row in rows]})
        return
    for row in rows:
        click.echo(row.sentence())
