"""The hob library: list, add one hob, import a CSV of hobs, match a hob to a stored gear.

A hob is checked the same way whether it comes from `add_hob` or from a CSV row: its
cells go through the column parsers of HOB_COLUMNS, then the cross-column checks. An
import is all or nothing: every row is checked first, every problem is reported with the
physical line number in the file (header = line 1), and only a good file is stored.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import msgspec
import psycopg
from psycopg import sql

from ..csv_reader import (
    CellError,
    Column,
    CsvError,
    CsvKind,
    Problem,
    declare,
    parse_number,
    parse_positive_whole,
    parse_text,
    read_cell,
    read_csv_file,
)
from ..db.listing import exact_records
from ..db.replacing import changed_fields, jobs_of, refuse_held
from ..errors import EngineError
from ..names import NAME_RULES, is_safe, said
from .gear_import import POSITIVE, parse_hand, parse_module_kind
from .hob_matching import ACCURACY_CLASSES, PURPOSES, HobChoice, choose_hob
from .models import ancestry
from .records import TOOTH_DEPTH, Hob, load_gear, load_hobs

# The hob's tooth profile (table hob's CHECK, reference §C1): the basic rack's, a tip protuberance,
# or a topping hob that also cuts the gear's tip.
PROFILES = ("standard", "protuberance", "topping")
HobImportError = CsvError   # a file of bad rows: `problems` holds one line per problem, in file order


class HobImport(msgspec.Struct, frozen=True):
    """What an import did: hobs new to the library, and hobs whose id was there already."""

    added: int
    updated: int
    kept: tuple[str, ...] = ()   # columns the file leaves out: a hob updated keeps its own values of them


def parse_accuracy_class(cell: str) -> str:
    if cell.upper() not in ACCURACY_CLASSES:
        raise CellError(f"is not one of {', '.join(ACCURACY_CLASSES)}")
    return cell.upper()


def parse_hob_id(cell: str) -> str:
    """The id is printed in the program's `; HOB …` comment: a safe hob name (engine/names.py)."""
    if not is_safe("hob", cell):
        raise CellError(f"is not a safe hob id: use {NAME_RULES['hob'].rule}")
    return cell


def parse_profile(cell: str) -> str:
    if cell.lower() not in PROFILES:
        raise CellError(f"is not one of {', '.join(PROFILES)}")
    return cell.lower()


def parse_purpose(cell: str) -> str:
    if cell.lower() not in PURPOSES:
        raise CellError(f"is not one of {', '.join(PURPOSES)}")
    return cell.lower()


declare(parse_accuracy_class, "accuracy class", f"write one of {', '.join(ACCURACY_CLASSES)}")
declare(parse_hob_id, "hob id", "write an id like H-M2-AA-R1")
declare(parse_purpose, "purpose", f"write one of {', '.join(PURPOSES)}")
declare(parse_profile, "profile", f"write one of {', '.join(PROFILES)}")

# Gashes a hob record may give: solid HSS catalogue hobs have 9–20 (12–16 for m1–m4, DIN 3968),
# multi-gash carbide and high-performance hobs up to about 30 (docs/reference/hobbing.md §C1); 40
# leaves room above those, and a count beyond it is a typing error (1000 would put i = gashes/starts
# far outside the range Hoffmeister's formula was fitted on and raise the feed it allows).
MAX_GASHES = 40

# In the order of the fields of records.Hob (and of seed_templates/hobs.csv).
HOB_COLUMNS: tuple[Column, ...] = (
    Column("id", parse_hob_id, required=True),
    Column("module", parse_number, required=True, unit="mm", **POSITIVE),
    Column("pressure_angle", parse_number, required=True, check=lambda v: 0 < v < 45, rule="is outside (0, 45)",
           unit="degrees"),
    Column("starts", parse_positive_whole, required=True),
    Column("tip_diameter", parse_number, required=True, unit="mm", **POSITIVE),
    Column("length", parse_number, required=True, unit="mm", **POSITIVE),
    Column("hand", parse_hand, required=True),
    Column("accuracy_class", parse_accuracy_class, required=True),
    Column("material", parse_text),
    Column("coating", parse_text),
    Column("purpose", parse_purpose),
    Column("tool_number", parse_positive_whole, check=lambda v: v <= 32000, rule="is above 32000"),
    Column("module_kind", parse_module_kind),
    Column("gashes", parse_positive_whole, check=lambda v: v <= MAX_GASHES,
           rule=f"is above {MAX_GASHES} (catalogue hobs have 9–20 gashes, multi-gash carbide hobs up to about 30)",
           hint=f"write the hob's gashes, 1 to {MAX_GASHES}"),
    Column("profile", parse_profile),
)
COLUMN_NAMES = tuple(column.name for column in HOB_COLUMNS)
HOB_KIND = CsvKind("hob", HOB_COLUMNS)
DEFAULTS = {"material": "HSS", "coating": "", "purpose": "cylindrical", "tool_number": 1, "gashes": 12,
            "profile": "standard"}
assert COLUMN_NAMES == Hob.__struct_fields__, "HOB_COLUMNS must follow records.Hob"


# --- one hob: cells → values and problems ------------------------------------------------

def _parse_cell(column: Column, cell: str, line: int | None, separator: str) -> tuple[Any, Problem | None]:
    """(value, problem) of one cell; an empty cell is the default (or missing if required)."""
    value, problem = read_cell(column, cell, line, separator)
    if problem and value is not None:   # a value that breaks its rule is not stored
        value = None
    return (DEFAULTS.get(column.name) if not cell else value), problem


def _check_tip_diameter(hob: dict[str, Any], line: int | None) -> Problem | None:
    """The hob's teeth are one tooth depth (2.25·m) high on each side of its body."""
    if hob["module"] is None or hob["tip_diameter"] is None:
        return None
    least = 2 * TOOTH_DEPTH * hob["module"]
    if hob["tip_diameter"] <= least:
        return Problem(line, "tip_diameter", f"{hob['tip_diameter']} is not greater than 2·2.25·module = "
                       f"{float(least):g} (two tooth depths)", "check the module and the tip diameter")
    return None


def _check_module_kind(hob: dict[str, Any], line: int | None) -> Problem | None:
    """A worm-wheel hob says which module its record gives: catalogues give the worm's axial
    module m_x (DIN 3975), and read as a normal module it couples the tangential feed to the wrong
    pitch (2 % at a lead angle of 11.6°). A cylindrical hob's module is normal (left empty: normal)."""
    kind, purpose = hob["module_kind"], hob["purpose"]
    if kind is None and purpose == "worm_wheel":
        return Problem(line, "module_kind", "is missing: a worm-wheel hob's record must say which module it gives",
                       "write axial (the worm's axial module m_x, as worm-wheel hobs are catalogued) or normal")
    if kind == "axial" and purpose != "worm_wheel":
        return Problem(line, "module_kind", "axial is for worm-wheel hobs (the module of the worm they copy)",
                       "write normal, or purpose worm_wheel")
    if kind is None:
        hob["module_kind"] = "normal"
    return None


def parse_hob(cells: dict[str, str], line: int | None = None,
              separator: str = ",") -> tuple[dict[str, Any], list[Problem]]:
    """The hob of named cells (every column; missing cells are empty) and its problems."""
    hob: dict[str, Any] = {}
    problems: list[Problem] = []
    for column in HOB_COLUMNS:
        hob[column.name], problem = _parse_cell(column, cells.get(column.name, "").strip(), line, separator)
        if problem:
            problems.append(problem)
    crossed = [problem for problem in (_check_tip_diameter(hob, line), _check_module_kind(hob, line)) if problem]
    return hob, problems + crossed


# --- the library -------------------------------------------------------------------------

def list_hobs(conn: psycopg.Connection) -> list[Hob]:
    """Every hob of the library, by id."""
    return load_hobs(conn)


_COLUMN_LIST = sql.SQL(", ").join(map(sql.Identifier, COLUMN_NAMES))
_VALUES = sql.SQL(", ").join(sql.Placeholder() * len(COLUMN_NAMES))
_INSERT = sql.SQL("INSERT INTO hob ({}) VALUES ({})").format(_COLUMN_LIST, _VALUES)
_EXPORT = sql.SQL("SELECT {} FROM hob ORDER BY id").format(_COLUMN_LIST)


def export_hobs(conn: psycopg.Connection) -> list[dict[str, Any]]:
    """Every hob of the library by id as `engine hobs import` reads it: its columns, each value as
    stored (the module in the record's own kind, every digit)."""
    return exact_records(conn.execute(_EXPORT))


def _cell(value: Any) -> str:
    """A field of a Hob as the text a CSV cell would hold (2.0 → "2")."""
    text = "" if value is None else str(value)
    return text[:-2] if isinstance(value, float) and text.endswith(".0") else text


def add_hob(conn: psycopg.Connection, hob: Hob) -> None:
    """Store one new hob; refuse a bad one (every problem named) or an id already there."""
    values, problems = parse_hob({name: _cell(getattr(hob, name)) for name in COLUMN_NAMES})
    if problems:
        told = "; ".join(f"{problem.column} {problem.what} ({problem.todo})" if problem.todo else
                         f"{problem.column} {problem.what}" for problem in problems)
        raise EngineError(f"hob {said('hob', hob.id) if hob.id else '(no id)'}: {told}; nothing stored")
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

def read_hobs(path: str | Path) -> list[dict[str, Any]]:
    """Every hob of the CSV file at `path`, checked, keyed by column name.
    Raises HobImportError listing every problem of every row, or EngineError."""
    return _read_hob_file(path)[0]


def _read_hob_file(path: str | Path) -> tuple[list[dict[str, Any]], tuple[str, ...]]:
    """(the hobs of the file, the columns its header gives)."""
    file = read_csv_file(path, HOB_KIND)
    if not file.records:
        raise EngineError(f"{path}: no hob rows; give one hob per line under the header")
    hobs, problems = [], []
    first_line: dict[str, tuple[int, str]] = {}   # id in upper case -> (line, id) where it is first
    for line, cells in file.rows():
        hob, row_problems = parse_hob(cells, line, file.separator)
        folded = hob["id"].upper() if hob["id"] is not None else None
        if folded in first_line:
            earlier, earlier_id = first_line[folded]
            case = f" as {earlier_id} (ids that differ only in case name one hob)" if earlier_id != hob["id"] else ""
            row_problems.append(Problem(line, "id", f"{hob['id']} is already on line {earlier}{case}",
                                        "give each hob once"))
        elif folded is not None:
            first_line[folded] = (line, hob["id"])
        problems += row_problems
        hobs.append(hob)
    if problems:
        raise HobImportError(path, problems)
    return hobs, tuple(name for name in COLUMN_NAMES if name in file.header)


def _upsert(given: tuple[str, ...]) -> sql.Composed:
    """INSERT every column (a new hob gets the defaults of the columns left out); on an id already
    in the library, UPDATE only the columns the file gives: a file in the columns of an older
    seed_templates/hobs.csv must not reset a hob's tool number, gashes or profile to the defaults
    (a program would call T1 for a hob set up as T5)."""
    updated = [name for name in COLUMN_NAMES if name != "id" and name in given]
    return _INSERT + sql.SQL(" ON CONFLICT (id) DO UPDATE SET {}").format(sql.SQL(", ").join(
        sql.SQL("{0} = EXCLUDED.{0}").format(sql.Identifier(name)) for name in updated))


JOBS_OF_HOBS = "SELECT hob_id, array_agg(id ORDER BY id) FROM job WHERE hob_id = ANY(%s) GROUP BY hob_id"
_LOCKED = sql.SQL("SELECT {} FROM hob WHERE id = ANY(%s) ORDER BY id FOR UPDATE").format(_COLUMN_LIST)


def import_hobs(conn: psycopg.Connection, path: str | Path, *, replace: bool = False) -> HobImport:
    """Insert or update (by id) every hob of the CSV file at `path`, all or nothing. `replace`: each
    stored hob is replaced whole, so the file must give every column. A hob a stored job was made
    with is changed in no column (engine.db.replacing)."""
    hobs, given = _read_hob_file(path)
    if replace and len(given) < len(COLUMN_NAMES):
        left_out = ", ".join(name for name in COLUMN_NAMES if name not in given)
        raise EngineError(f"{path}: --replace replaces each stored hob whole, but the file leaves out {left_out}; "
                          "nothing imported: give every column (`engine hobs list --csv` writes them), or import "
                          "without --replace to keep each hob's own values of those")
    ids = [hob["id"] for hob in hobs]
    twin = conn.execute("SELECT id, new FROM hob, unnest(%s::text[]) AS new WHERE upper(id) = upper(new) AND id <> new "
                        "LIMIT 1", (ids,)).fetchone()
    if twin:
        raise EngineError(f"{path}: {_same_but_case(twin[1], twin[0])}; nothing imported")
    try:
        with conn.transaction():
            stored = {hob["id"]: hob for hob in exact_records(conn.execute(_LOCKED, (ids,)))}
            changes = changed_fields(stored, hobs, "id", [name for name in given if name != "id"])
            refuse_held(path, "hob", changes, jobs_of(conn, JOBS_OF_HOBS, [change.key for change in changes]))
            with conn.cursor() as cursor:
                cursor.executemany(_upsert(given), [[hob[name] for name in COLUMN_NAMES] for hob in hobs])
    except (psycopg.errors.IntegrityError, psycopg.errors.DataError) as error:
        raise EngineError(f"{path}: the database refused the hobs "
                          f"({error.diag.message_primary or error}); nothing imported") from error
    kept = tuple(name for name in COLUMN_NAMES if name not in given) if stored else ()
    return HobImport(added=len(ids) - len(stored), updated=len(stored), kept=kept)


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

