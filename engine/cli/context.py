"""What every command shares: the database connection of the invocation, and JSON output."""
from __future__ import annotations

import json
from contextlib import contextmanager

import click


@contextmanager
def connection(ctx, migrated: bool = True):
    """The database of --database-url (else DATABASE_URL, PG*, the embedded server), migrations
    required current unless the command applies them."""
    from ..db.connection import connect
    from ..db.migrate import require_current

    with connect(ctx.obj["database_url"]) as conn:
        if migrated:
            require_current(conn)
        yield conn


def emit_json(payload: dict) -> None:
    click.echo(json.dumps(payload, default=str))   # design notes §9: one JSON object on one line
