"""Storing gears read from CSV (engine.gears.gear_import reads and checks them first): every row
in one COPY and one upsert, all or nothing; stored ids are refused unless --replace, which prints
each change (old -> new), and refuses a change to a gear a stored job was made from
(engine.db.replacing). Also which classes a gear may be in, for the reader's checks."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import msgspec
import psycopg
from psycopg import sql

from ..csv_reader import Problem
from ..db.origin import MADE_HERE_SQL
from ..db.replacing import Change, changed_fields, jobs_of, plain, refuse_held
from ..errors import EngineError
from .classify import classify
from .gear_import import COLUMNS, FROM_TREE, Classes, GearImportError, read_gears

# templated: the class has rows, or its released version has (a plant holds only the released
# versions the head office replicated, not the rows being edited: docs/design.md §12)
INSTALLED = ("SELECT g.name, EXISTS (SELECT 1 FROM class_template(g.name)) OR EXISTS (SELECT 1 FROM "
             "template_version_rows v WHERE v.gear_class = g.name AND v.version = released_version(g.name) "
             "AND v.rows <> '[]'), "
             "g.name IN (SELECT name FROM classes_and_below(ARRAY['cylindrical'])) FROM gear_class g")


def installed_classes(conn: psycopg.Connection) -> Classes:
    """The classes a gear can be in (leaves, and unit classes that others derive from, like spur),
    and the cylindrical ones (whose diameters are checked)."""
    rows = conn.execute(INSTALLED).fetchall()
    return Classes({name: templated for name, templated, _ in rows},
                   frozenset(name for name, _, cylindrical in rows if cylindrical))


_COLUMN_LIST = sql.SQL(", ").join(sql.Identifier(column.column) for column in COLUMNS)
_COPY = sql.SQL("COPY gear_import ({}) FROM STDIN").format(_COLUMN_LIST)
_UPSERT = sql.SQL(
    "INSERT INTO gear ({columns}) SELECT {columns} FROM gear_import "
    "ON CONFLICT (id) DO UPDATE SET {updates}").format(
    columns=_COLUMN_LIST,
    updates=sql.SQL(", ").join(
        sql.SQL("{0} = EXCLUDED.{0}").format(sql.Identifier(column.column))
        for column in COLUMNS if column.column != "id"))
_EXISTING = sql.SQL("SELECT {} FROM gear WHERE id = ANY(%s) ORDER BY id FOR UPDATE").format(_COLUMN_LIST)


class GearImport(msgspec.Struct, frozen=True):
    """What an import did: how many gears it stored, which of them replaced stored gears, and what
    changed in those (field by field)."""

    imported: int
    replaced: tuple[int, ...] = ()
    changes: tuple[Change, ...] = ()

    def change_lines(self) -> list[str]:
        """One line per changed field (`gear 42: module 2 → 3`), and a line for a replaced gear the file
        left as it was."""
        changed = {change.key for change in self.changes}
        return ([change.said("gear") for change in self.changes]
                + [f"gear {gear_id}: unchanged" for gear_id in self.replaced if gear_id not in changed])

    def as_json(self) -> dict[str, Any]:
        return {"imported": self.imported, "replaced": list(self.replaced),
                "changes": [{"gear_id": c.key, "field": c.field, "old": plain(c.old), "new": plain(c.new)}
                            for c in self.changes]}


def _changes(stored: dict[int, tuple], gears: list[dict[str, Any]]) -> list[Change]:
    """Per replaced gear, per field, the stored value and the file's, where they differ."""
    named = {gear_id: {column.name: value for column, value in zip(COLUMNS, row)} for gear_id, row in stored.items()}
    return changed_fields(named, gears, "gear_id", [column.name for column in COLUMNS])


# this database's jobs only: a plant's job of gear 44 is of the plant's gear 44 (issue 33, engine.db.origin)
JOBS_OF_GEARS = ("SELECT gear_id, array_agg(id ORDER BY id) FROM job WHERE gear_id = ANY(%s) AND "
                 + MADE_HERE_SQL.format(id="id") + " GROUP BY gear_id")


def _refuse_existing(path: Path, stored: dict[int, tuple], gears: list[dict[str, Any]]) -> None:
    """Without --replace, a gear_id already stored is refused: an import must not overwrite a gear
    that jobs and programs were made for without saying so."""
    problems = [Problem(gear["line"], "gear_id", f"gear {gear['gear_id']} already exists",
                        "give a new gear_id, or import with --replace to overwrite it (the changes are printed)")
                for gear in gears if gear["gear_id"] in stored]
    if problems:
        raise GearImportError(path, problems)


def _store(conn: psycopg.Connection, path: Path, gears: list[dict[str, Any]], replace: bool) -> GearImport:
    """All gears in one transaction: the stored ones read (and locked) first, refused unless `replace`;
    then COPY into a temporary table and one INSERT … ON CONFLICT."""
    try:
        with conn.transaction():
            rows = conn.execute(_EXISTING, ([gear["gear_id"] for gear in gears],)).fetchall()
            stored = {row[0]: row for row in rows}
            if not replace:
                _refuse_existing(path, stored, gears)
            changes = _changes(stored, gears)
            refuse_held(path, "gear", changes, jobs_of(conn, JOBS_OF_GEARS, [change.key for change in changes]))
            conn.execute("CREATE TEMPORARY TABLE gear_import (LIKE gear) ON COMMIT DROP")
            with conn.cursor().copy(_COPY) as copy:
                for gear in gears:
                    copy.write_row([gear[column.name] for column in COLUMNS])
            conn.execute(_UPSERT)
            conn.execute("DROP TABLE gear_import")
    except (psycopg.errors.IntegrityError, psycopg.errors.DataError) as error:
        message = error.diag.message_primary or str(error)
        raise EngineError(f"{path}: the database refused the gears ({message}); "
                          "nothing imported") from error
    return GearImport(len(gears), tuple(sorted(stored)), tuple(changes))


def import_gears(conn: psycopg.Connection, path: str | Path, *, replace: bool = False) -> GearImport:
    """Import every gear of the CSV file at `path`, all or nothing. A gear_id already stored is
    refused unless `replace`, which overwrites it and returns what changed."""
    path = Path(path)
    classes = installed_classes(conn)
    gears = read_gears(path, classes)
    if replace:
        _count_stored_units(conn, gears, classes)
    return _store(conn, path, gears, replace)


STORED_UNITS = "SELECT gear_id, count(*) FROM gear_unit WHERE gear_id = ANY(%s) GROUP BY gear_id"


def _count_stored_units(conn: psycopg.Connection, gears: list[dict[str, Any]], classes: Classes) -> None:
    """A gear the file names no class for, replacing a stored gear with further units (`engine gears
    units`), is classified with those units counted: the tree's first question (engine.gears.classify)
    is whether it has any, and the gear file has no column for them. The class must be installed."""
    from_tree = [gear for gear in gears if gear.get(FROM_TREE)]
    counts: dict[int, int] = dict(conn.execute(STORED_UNITS, ([gear["gear_id"] for gear in from_tree],)).fetchall())
    for gear in from_tree:
        if counts.get(gear["gear_id"]):
            found = classify({**gear, "units": counts[gear["gear_id"]]}).gear_class
            if found and classes.templated.get(found):
                gear["gear_class"] = found


def identical_gears(conn: psycopg.Connection, gears: list[dict[str, Any]]) -> set[int]:
    """The ids of `gears` (as read_gears gives them) that are stored with every field as given."""
    stored = {row[0]: row for row in conn.execute(_EXISTING, ([gear["gear_id"] for gear in gears],))}
    return set(stored) - {change.key for change in _changes(stored, gears)}
