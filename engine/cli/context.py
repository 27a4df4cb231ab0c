"""What every command shares: the database connection of the invocation, and JSON output."""
from __future__ import annotations

import json
from contextlib import contextmanager

import click
import msgspec


@contextmanager
def connection(ctx, migrated: bool = True):
    """The database of --database-url (else DATABASE_URL, PG*, the embedded server), migrations
    required current unless the command applies them. The command starts outside any
    transaction, so what it stores in a transaction of its own is committed when that ends
    (program files are written only then: engine.programs.outputs); the rest is committed
    when the command ends."""
    from ..db.connection import connect
    from ..db.migrate import require_current

    # the check's reads run in autocommit, each its own statement: no BEGIN and COMMIT round trips
    # for them (issue 28: start-up); the command then starts idle, in transactions as always
    with connect(ctx.obj["database_url"], autocommit=migrated) as conn:
        if migrated:
            require_current(conn)
            conn.autocommit = False
        yield conn


def keyed(record: dict, **names: str) -> dict:
    """The record with its keys renamed to the names every --json uses (gear_id, job_id,
    program_id, hob_id, class): keyed(record_dict(hob), id="hob_id"); gear_class is always class."""
    names = {"gear_class": "class", **names}
    return {names.get(key, key): value for key, value in record.items()}


def record_dict(record) -> dict:
    """A record (a msgspec.Struct, or an importer's dataclass) as the plain dict --json writes, its
    nested records and lists included, as dataclasses.asdict gave (tuples as lists: JSON has no tuple)."""
    return msgspec.to_builtins(record, str_keys=True, enc_hook=str)   # enc_hook: as json.dumps default=str


def emit_json(payload: dict) -> None:
    click.echo(json.dumps(payload, default=str))   # design notes §9: one JSON object on one line


CONFIG = "engine.config"   # ctx.meta: the config file's settings (engine.programs.config), read once per invocation


def settings(ctx):
    """The settings of the config file (defaults when the command runs outside `engine`)."""
    from ..programs.config import Config

    return ctx.meta.get(CONFIG) or Config()
