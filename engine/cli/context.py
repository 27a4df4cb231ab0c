"""What every command shares: the database connection of the invocation, and JSON output."""
from __future__ import annotations

import json
from contextlib import contextmanager

import click


@contextmanager
def connection(ctx, migrated: bool = True):
    """The database of --database-url (else DATABASE_URL, PG*, the embedded server), migrations
    required current unless the command applies them. The command starts outside any
    transaction, so what it stores in a transaction of its own is committed when that ends
    (program files are written only then: engine.programs.outputs); the rest is committed
    when the command ends."""
    from ..db.connection import connect
    from ..db.migrate import require_current

    with connect(ctx.obj["database_url"]) as conn:
        if migrated:
            require_current(conn)
            conn.commit()   # the check's read ends here: the command starts idle
        yield conn


def emit_json(payload: dict) -> None:
    click.echo(json.dumps(payload, default=str))   # design notes §9: one JSON object on one line
