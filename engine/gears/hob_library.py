"""The hob library: list, add one hob, import a CSV of hobs, match a hob to a stored gear.

A hob is checked the same way whether it comes from `add_hob` or from a CSV row: its
cells go through the column parsers of HOB_COLUMNS, then the cross-column checks. An
import is all or nothing: every row is checked first, every problem is reported with the
physical line number in the file (header = line 1), and only a good file is stored.
"""
from __future__ import annotations

from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import psycopg
from psycopg import sql

from ..errors import EngineError
from ..names import NAME_RULES, is_safe, said, shown
from .gear_import import (POSITIVE, CellError, Column, parse_hand, parse_number,
                          parse_positive_whole, parse_text, read_records)
from .hob_matching import ACCURACY_CLASSES, PURPOSES, HobChoice, choose_hob
from .models import ancestry
from .records import TOOTH_DEPTH, Hob, load_gear, load_hobs


class HobImportError(EngineError):
    """A hob file with bad rows. `problems` holds one line per problem, in file order."""

    def __init__(self, path: Any, problems: list[str], bad_rows: int) -> None:
        super().__init__(f"{path}: {bad_rows} bad row(s); nothing imported")
        self.problems = problems
        self.bad_rows = bad_rows


@dataclass(frozen=True)
class HobImport:
    """What an import did: hobs new to the library, and hobs whose id was there already."""

    added: int
    updated: int


def parse_accuracy_class(cell: str) -> str:
    if cell.upper() not in ACCURACY_CLASSES:
        raise CellError(f"is not one of {', '.join(ACCURACY_CLASSES)}")
    return cell.upper()


def parse_hob_id(cell: str) -> str:
    """The id is printed in the program's `; HOB …` comment: a safe hob name (engine/names.py)."""
    if not is_safe("hob", cell):
        raise CellError(f"is not a safe hob id: use {NAME_RULES['hob'].rule}")
    return cell


def parse_purpose(cell: str) -> str:
    if cell.lower() not in PURPOSES:
        raise CellError(f"is not one of {', '.join(PURPOSES)}")
    return cell.lower()


# In the order of the fields of records.Hob (and of seed_templates/hobs.csv).
HOB_COLUMNS: tuple[Column, ...] = (
    Column("id", parse_hob_id, required=True),
    Column("module", parse_number, required=True, **POSITIVE),
    Column("pressure_angle", parse_number, required=True, check=lambda v: 0 < v < 45, rule="is outside (0, 45)"),
    Column("starts", parse_positive_whole, required=True),
    Column("tip_diameter", parse_number, required=True, **POSITIVE),
    Column("length", parse_number, required=True, **POSITIVE),
    Column("hand", parse_hand, required=True),
    Column("accuracy_class", parse_accuracy_class, required=True),
    Column("material", parse_text),
    Column("coating", parse_text),
    Column("purpose", parse_purpose),
    Column("tool_number", parse_positive_whole, check=lambda v: v <= 32000, rule="is above 32000"),
)
COLUMN_NAMES = tuple(column.name for column in HOB_COLUMNS)
DEFAULTS = {"material": "HSS", "coating": "", "purpose": "cylindrical", "tool_number": 1}
assert COLUMN_NAMES == tuple(field.name for field in fields(Hob)), "HOB_COLUMNS must follow records.Hob"


# --- one hob: cells → values and problems ------------------------------------------------

def _parse_cell(column: Column, cell: str) -> tuple[Any, str | None]:
    """(value, problem) of one cell; an empty cell is the default (or missing if required)."""
    if not cell:
        return DEFAULTS.get(column.name), (f"{column.name} is missing" if column.required else None)
    try:
        value = column.parse(cell)
    except CellError as error:
        return None, f"{column.name} {shown(cell)} {error}"
    if column.check is not None and not column.check(value):
        return None, f"{column.name} {cell} {column.rule}"
    return value, None


def _check_tip_diameter(hob: dict[str, Any]) -> str | None:
    """The hob's teeth are one tooth depth (2.25·m) high on each side of its body."""
    if hob["module"] is None or hob["tip_diameter"] is None:
        return None
    least = 2 * TOOTH_DEPTH * hob["module"]
    if hob["tip_diameter"] <= least:
        return (f"tip_diameter {hob['tip_diameter']} is not greater than 2·2.25·module = {float(least):g} "
                "(two tooth depths)")
    return None


def parse_hob(cells: dict[str, str]) -> tuple[dict[str, Any], list[str]]:
    """The hob of named cells (every column; missing cells are empty) and its problems."""
    hob: dict[str, Any] = {}
    problems: list[str] = []
    for column in HOB_COLUMNS:
        hob[column.name], problem = _parse_cell(column, cells.get(column.name, "").strip())
        if problem:
            problems.append(problem)
    tip_problem = _check_tip_diameter(hob)
    return hob, problems + ([tip_problem] if tip_problem else [])


# --- the library -------------------------------------------------------------------------

def list_hobs(conn: psycopg.Connection) -> list[Hob]:
    """Every hob of the library, by id."""
    return load_hobs(conn)


_COLUMN_LIST = sql.SQL(", ").join(map(sql.Identifier, COLUMN_NAMES))
_VALUES = sql.SQL(", ").join(sql.Placeholder() * len(COLUMN_NAMES))
_INSERT = sql.SQL("INSERT INTO hob ({}) VALUES ({})").format(_COLUMN_LIST, _VALUES)
_UPSERT = _INSERT + sql.SQL(" ON CONFLICT (id) DO UPDATE SET {}").format(sql.SQL(", ").join(
    sql.SQL("{0} = EXCLUDED.{0}").format(sql.Identifier(name)) for name in COLUMN_NAMES if name != "id"))


def _cell(value: Any) -> str:
    """A field of a Hob as the text a CSV cell would hold (2.0 → "2")."""
    text = "" if value is None else str(value)
    return text[:-2] if isinstance(value, float) and text.endswith(".0") else text


def add_hob(conn: psycopg.Connection, hob: Hob) -> None:
    """Store one new hob; refuse a bad one (every problem named) or an id already there."""
    values, problems = parse_hob({name: _cell(getattr(hob, name)) for name in COLUMN_NAMES})
    if problems:
        raise EngineError(f"hob {said('hob', hob.id) if hob.id else '(no id)'}: {'; '.join(problems)}; nothing stored")
    exists = f"hob {values['id']} already exists; choose another id, or change it with `engine hobs import FILE.csv`"
    found = conn.execute("SELECT id FROM hob WHERE upper(id) = upper(%s)", (values["id"],)).fetchone()
    if found:
        raise EngineError(exists if found[0] == values["id"] else _same_but_case(values["id"], found[0]))
    try:
        with conn.transaction():
            conn.execute(_INSERT, [values[name] for name in COLUMN_NAMES])
    except psycopg.errors.UniqueViolation:
        raise EngineError(exists) from None
    except (psycopg.errors.IntegrityError, psycopg.errors.DataError) as error:
        raise EngineError(f"hob {values['id']}: the database refused it "
                          f"({error.diag.message_primary or error}); nothing stored") from error


# --- a CSV file of hobs ------------------------------------------------------------------

def _header(path: Path, cells: list[str]) -> list[str]:
    names = [cell.lower() for cell in cells]
    unknown = [name for name in names if name not in COLUMN_NAMES]
    twice = sorted({name for name in names if names.count(name) > 1})
    missing = [column.name for column in HOB_COLUMNS if column.required and column.name not in names]
    problems = ([f"unknown column(s) {', '.join(map(repr, unknown))} (known: {', '.join(COLUMN_NAMES)})"]
                if unknown else [])
    problems += [f"column(s) named twice: {', '.join(twice)}"] if twice else []
    problems += [f"missing required column(s) {', '.join(missing)}"] if missing else []
    if problems:
        raise EngineError(f"{path}: " + "; ".join(problems))
    return names


def _row(names: list[str], cells: list[str]) -> tuple[dict[str, Any], list[str]]:
    hob, problems = parse_hob(dict(zip(names, cells)))
    if len(cells) > len(names) and any(cells[len(names):]):
        problems.append(f"{len(cells)} cells but the header names {len(names)} columns")
    return hob, problems


def read_hobs(path: str | Path) -> list[dict[str, Any]]:
    """Every hob of the CSV file at `path`, checked, keyed by column name.
    Raises HobImportError listing every problem of every row, or EngineError."""
    path = Path(path)
    records = read_records(path)
    if len(records) < 2:
        raise EngineError(f"{path} has no hob rows")
    names = _header(path, records[0][1])
    hobs, problems, bad_lines, first_line = [], [], set(), {}
    for line, cells in records[1:]:
        hob, row_problems = _row(names, cells)
        folded = hob["id"].upper() if hob["id"] is not None else None
        if folded in first_line:
            earlier, earlier_id = first_line[folded]
            case = f" as {earlier_id} (ids that differ only in case name one hob)" if earlier_id != hob["id"] else ""
            row_problems.append(f"id {hob['id']} is already on line {earlier}{case}")
        elif folded is not None:
            first_line[folded] = (line, hob["id"])
        problems += [f"line {line}: {problem}" for problem in row_problems]
        bad_lines |= {line} if row_problems else set()
        hobs.append(hob)
    if problems:
        raise HobImportError(path, problems, len(bad_lines))
    return hobs


def import_hobs(conn: psycopg.Connection, path: str | Path) -> HobImport:
    """Insert or update (by id) every hob of the CSV file at `path`, all or nothing."""
    hobs = read_hobs(path)
    ids = [hob["id"] for hob in hobs]
    twin = conn.execute("SELECT id, new FROM hob, unnest(%s::text[]) AS new WHERE upper(id) = upper(new) AND id <> new "
                        "LIMIT 1", (ids,)).fetchone()
    if twin:
        raise EngineError(f"{path}: {_same_but_case(twin[1], twin[0])}; nothing imported")
    try:
        with conn.transaction():
            existing = conn.execute("SELECT count(*) FROM hob WHERE id = ANY(%s)", (ids,)).fetchone()[0]
            with conn.cursor() as cursor:
                cursor.executemany(_UPSERT, [[hob[name] for name in COLUMN_NAMES] for hob in hobs])
    except (psycopg.errors.IntegrityError, psycopg.errors.DataError) as error:
        raise EngineError(f"{path}: the database refused the hobs "
                          f"({error.diag.message_primary or error}); nothing imported") from error
    return HobImport(added=len(ids) - existing, updated=existing)


def _same_but_case(given: str, stored: str) -> str:
    """A hob id is one hob whatever its case (an operator reading `; HOB …` cannot tell them apart)."""
    return f"hob {given} is hob {stored} of the library (ids that differ only in case name one hob); use {stored}"


# --- matching ----------------------------------------------------------------------------

def default_purpose(conn: psycopg.Connection, gear_class: str | None) -> str:
    """Worm wheels (the class or an ancestor is worm_wheel) need a worm-wheel hob."""
    if gear_class and "worm_wheel" in ancestry(conn, gear_class):
        return "worm_wheel"
    return "cylindrical"


def match_hob(conn: psycopg.Connection, gear_id: int, *, purpose: str | None = None,
              shift_travel: float = 0.0) -> HobChoice:
    """The library's hob for the stored gear, with the reason (or NoHobError)."""
    gear = load_gear(conn, gear_id)
    chosen_purpose = purpose or default_purpose(conn, gear.gear_class)
    return choose_hob(gear, load_hobs(conn), purpose=chosen_purpose, shift_travel=shift_travel)

