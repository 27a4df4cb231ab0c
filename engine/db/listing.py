"""Rows read for a person or a program to look at (issue 16: the list and show commands): plain
records with the common key names, filters that are absent when not given, and deleting a row
only when nothing refers to it."""
from __future__ import annotations

from datetime import date
from decimal import Decimal
from typing import TYPE_CHECKING, Any

import msgspec

from ..errors import EngineError
from .connection import scalar

if TYPE_CHECKING:
    from psycopg import Cursor
    from psycopg.rows import TupleRow

    from .connection import Connection

# A filter not given is NULL: each list query holds every condition as `(%(x)s IS NULL OR …)`, so
# its SQL is one static text and every value a bound parameter; days compare in the session's zone.


def plain(value: Any) -> Any:
    """A column's value as JSON and a table take it: numeric as float, the rest as it is."""
    return float(value) if isinstance(value, Decimal) else value


def records(cursor: Cursor[TupleRow]) -> list[dict[str, Any]]:
    """The cursor's rows as dicts keyed by the column names the query gave them."""
    names = [column.name for column in cursor.description or ()]
    return [{name: plain(value) for name, value in zip(names, row)} for row in cursor]


def exact_records(cursor: Cursor[TupleRow]) -> list[dict[str, Any]]:
    """The cursor's rows as dicts keyed by the column names, each value as stored (numeric as the
    Decimal of its digits): what an export writes, so that its import stores the same numbers."""
    names = [column.name for column in cursor.description or ()]
    return [dict(zip(names, row)) for row in cursor]


def one_record(cursor: Cursor[TupleRow], kind: str, key: Any, listing: str) -> dict[str, Any]:
    """The one row found, or EngineError naming the thing and the list that shows what exists."""
    found = records(cursor)
    if not found:
        raise EngineError(f"{kind} {key} does not exist; `{listing}` shows what does")
    return found[0]


def day_range(since: date | None, until: date | None) -> dict[str, date | None]:
    """The parameters of DAY_FILTERS; EngineError if the range is empty by construction."""
    if since and until and since > until:
        raise EngineError(f"--since {since} is after --until {until}; give the earlier day first")
    return {"since": since, "until": until}


def require_class(conn: Connection, name: str | None) -> None:
    """A --class filter must name a class: a typo would otherwise list nothing, silently."""
    if name is not None and conn.execute("SELECT 1 FROM gear_class WHERE name = %s", (name,)).fetchone() is None:
        raise EngineError(f"class {name!r} does not exist; `engine template list` shows the classes")


class Reference(msgspec.Struct, frozen=True):
    """Rows that refer to a row and keep it from being deleted: what they are, how to count them."""
    what: str        # "job", "golden test": the refusal names them (and adds an s for more than one)
    count_sql: str   # one bound parameter: the row's id


class Deletion(msgspec.Struct, frozen=True):
    """How one kind of row is deleted: its lock (FOR UPDATE, so no reference can be added between
    the count and the delete), what refers to it, and the delete itself."""
    kind: str
    lock_sql: str            # returns the row's one-line description, or nothing
    references: tuple[Reference, ...]
    delete_sql: str
    listing: str


class NotConfirmed(EngineError):
    """A delete asked without --yes: what would go, nothing deleted."""


def delete_row(conn: Connection, deletion: Deletion, key: Any, yes: bool) -> str:
    """Delete the row if nothing refers to it and the user said yes; its description. Otherwise
    EngineError: the row unknown, what refers to it, or what would be deleted. All in one
    transaction: a refusal deletes nothing."""
    with conn.transaction():
        described = _locked(conn, deletion, key)
        _refuse_referenced(conn, deletion, key)
        if not yes:
            raise NotConfirmed(f"would delete {described}; nothing deleted: add --yes to delete it")
        conn.execute(deletion.delete_sql, (key,))
    return described


def _locked(conn: Connection, deletion: Deletion, key: Any) -> str:
    found = conn.execute(deletion.lock_sql, (key,)).fetchone()
    if found is None:
        raise EngineError(f"{deletion.kind} {key} does not exist; `{deletion.listing}` shows what does")
    return str(found[0])


def _refuse_referenced(conn: Connection, deletion: Deletion, key: Any) -> None:
    counts = [(scalar(conn.execute(ref.count_sql, (key,))), ref.what) for ref in deletion.references]
    held = [f"{count} {what}{'' if count == 1 else 's'}" for count, what in counts if count]
    if held:
        raise EngineError(f"{deletion.kind} {key} has {' and '.join(held)}; nothing deleted: a {deletion.kind} "
                          "that other records refer to is kept")
