"""Adding machine records from a CSV file (`engine machines import`): the columns of the machine
table, as `engine machines list --csv` writes them and seed_templates/machines.csv holds them;
name, kind and dialect are required, an empty cell takes the column's default. A shop adds its own
lathe or hobber here instead of in SQL.

Only new machines are added: a record that exists is the one its stored programs were proved
against, so changing its travel or its control's facts is a deliberate edit in SQL, not a side
effect of a file (docs/guide/machines-and-simulation.md). A kind and dialect the verifier has no
grammar for is refused where it enters, naming the ones it has: such a machine could never be
given a program. All or nothing: any bad row stops the file, nothing stored."""
from __future__ import annotations

from dataclasses import fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

import psycopg
from psycopg import sql

from ..csv_reader import Column, CsvKind, parse_text, read_csv_file
from ..errors import EngineError
from ..names import shown
from .records import Machine

if TYPE_CHECKING:
    from ..db.connection import Connection

REQUIRED = ("name", "kind", "dialect")
# The columns of the machine table (the record's fields), as text the database converts.
MACHINE_KIND = CsvKind("machine", tuple(Column(spec.name, parse_text, required=spec.name in REQUIRED)
                                        for spec in fields(Machine)))


def read_machines(path: str | Path) -> list[dict[str, Any]]:
    """The rows of a machines CSV as {column: text}, an empty cell None (the column's default);
    a row without a name, kind or dialect is refused, naming its line."""
    machines = []
    for line, row in read_csv_file(path, MACHINE_KIND).rows():
        machine = {key: (value if value != "" else None) for key, value in row.items()}
        missing = [column for column in REQUIRED if machine[column] is None]
        if missing:
            raise EngineError(f"{path}: line {line} gives no {missing[0]}; every machine needs its name, kind "
                              "(hobber or lathe) and dialect; nothing imported")
        machines.append(machine)
    return machines


def import_machines(conn: Connection, path: str | Path, grammars: set[tuple[str, str]]) -> list[str]:
    """Add every machine of the CSV file at `path`, all or nothing; `grammars`: the (kind, dialect)
    pairs the verifier reads. Returns the names added."""
    machines = read_machines(path)
    for machine in machines:
        _refuse_unknown_grammar(path, machine, grammars)
    names = [machine["name"] for machine in machines]
    _refuse_repeated(path, names)
    _refuse_existing(conn, path, names)
    with conn.transaction():
        for machine in machines:
            _insert(conn, path, machine)
    return names


def _refuse_unknown_grammar(path, machine: dict, grammars: set[tuple[str, str]]) -> None:
    if (machine["kind"], machine["dialect"]) not in grammars:
        known = ", ".join(f"{kind} {dialect}" for kind, dialect in sorted(grammars))
        raise EngineError(f"{path}: machine {shown(machine['name'])} is a {shown(machine['kind'])} of dialect "
                          f"{shown(machine['dialect'])}, which no grammar of the verifier reads; use one of: "
                          f"{known}; nothing imported")


def _refuse_repeated(path, names: list[str]) -> None:
    repeated = sorted({name for name in names if names.count(name) > 1})
    if repeated:
        raise EngineError(f"{path}: machine {shown(repeated[0])} is given twice; give each machine once; "
                          "nothing imported")


def _refuse_existing(conn: Connection, path, names: list[str]) -> None:
    found = conn.execute("SELECT name FROM machine WHERE name = ANY(%s) ORDER BY name", (names,)).fetchone()
    if found:
        raise EngineError(f"{path}: machine {shown(found[0])} exists; its stored programs were proved against its "
                          "record, so change it in SQL (UPDATE machine …) or give the new machine another name; "
                          "nothing imported")


def _insert(conn: Connection, path, machine: dict) -> None:
    """One record; a value the table's checks refuse (a negative spindle limit, text for a number)
    names the machine, inside the file's transaction (nothing of the file is stored)."""
    given = {column: value for column, value in machine.items() if value is not None}   # empty: the default
    try:
        conn.execute(sql.SQL("INSERT INTO machine ({}) VALUES ({})").format(
            sql.SQL(", ").join(map(sql.Identifier, given)), sql.SQL(", ").join(sql.Placeholder() * len(given))),
            list(given.values()))
    except (psycopg.errors.IntegrityError, psycopg.errors.DataError) as error:
        raise EngineError(f"{path}: the database refused machine {shown(machine['name'])} "
                          f"({error.diag.message_primary or error}); nothing imported") from error
